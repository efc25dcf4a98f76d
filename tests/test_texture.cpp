// Textures against Mitsuba 3: the values its `bitmap` (every filter, wrap mode and raw setting, on an
// RGB and a grey PNG) and `checkerboard` return at the same uv points, as printed by
// tests/data/make_texture_reference.py; textured materials in a render against a Mitsuba
// reference. Bad image files and unsupported texture parameters are clean errors.
#include <gtest/gtest.h>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <jpeglib.h>  // after <cstdio>: it uses FILE
#include <glm/gtc/matrix_transform.hpp>
#include "core/error.h"
#include "support/bsdf_xml.h"
#include "support/run.h"
#include "film/film.h"
#include "film/image_io.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/render.h"
#include "support/stats.h"
#include "texture/texture.h"

using namespace candela;

namespace {

struct BitmapCase {
    const char* file;
    const char* filter;
    const char* wrap;
    bool raw;
    float u, v, r, g, b;
};

// file, filter, wrap, raw, u, v, r, g, b  (Mitsuba 3.9.1, scalar_rgb)
const BitmapCase kBitmap[] = {
    {"rgb3x2.png", "bilinear", "repeat", false, 0.1f, 0.2f, 0.0157311019f, 0.425375491f, 0.189390272f},
    {"rgb3x2.png", "bilinear", "repeat", false, 0.5f, 0.5f, 0.977986634f, 0.500758827f, 0.607930183f},
    {"rgb3x2.png", "bilinear", "repeat", false, 0.9f, 0.85f, 0.146475226f, 0.040550407f, 0.161879197f},
    {"rgb3x2.png", "bilinear", "repeat", false, 1.3f, -0.2f, 0.3984209f, 0.394715428f, 0.369413257f},
    {"rgb3x2.png", "bilinear", "repeat", false, -0.45f, 1.7f, 0.876167834f, 0.767847955f, 0.798634887f},
    {"rgb3x2.png", "bilinear", "repeat", false, 2.05f, 0.55f, 0.0532976352f, 0.160381854f, 0.143821925f},
    {"rgb3x2.png", "bilinear", "repeat", false, 0.0f, 0.0f, 0.0675412789f, 0.160823509f, 0.253776938f},
    {"rgb3x2.png", "bilinear", "repeat", false, 0.999f, 0.001f, 0.0677748695f, 0.160666853f, 0.256277382f},
    {"rgb3x2.png", "bilinear", "repeat", true, 0.1f, 0.2f, 0.0834509805f, 0.612392187f, 0.265254885f},
    {"rgb3x2.png", "bilinear", "repeat", true, 0.5f, 0.5f, 0.990196109f, 0.509803951f, 0.750980377f},
    {"rgb3x2.png", "bilinear", "repeat", true, 0.9f, 0.85f, 0.362980455f, 0.15184316f, 0.18227458f},
    {"rgb3x2.png", "bilinear", "repeat", true, 1.3f, -0.2f, 0.401568502f, 0.407843024f, 0.387137115f},
    {"rgb3x2.png", "bilinear", "repeat", true, -0.45f, 1.7f, 0.919862688f, 0.78737253f, 0.826372445f},
    {"rgb3x2.png", "bilinear", "repeat", true, 2.05f, 0.55f, 0.150745258f, 0.265411735f, 0.176353082f},
    {"rgb3x2.png", "bilinear", "repeat", true, 0.0f, 0.0f, 0.198039234f, 0.290196121f, 0.286274523f},
    {"rgb3x2.png", "bilinear", "repeat", true, 0.999f, 0.001f, 0.198896319f, 0.29049015f, 0.288734555f},
    {"rgb3x2.png", "bilinear", "mirror", false, 0.1f, 0.2f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "bilinear", "mirror", false, 0.5f, 0.5f, 0.977986634f, 0.500758827f, 0.607930183f},
    {"rgb3x2.png", "bilinear", "mirror", false, 0.9f, 0.85f, 0.215860412f, 0.0144438688f, 0.00212468905f},
    {"rgb3x2.png", "bilinear", "mirror", false, 1.3f, -0.2f, 0.413150847f, 0.0313687287f, 0.686344266f},
    {"rgb3x2.png", "bilinear", "mirror", false, -0.45f, 1.7f, 0.816729248f, 0.164134368f, 0.251885831f},
    {"rgb3x2.png", "bilinear", "mirror", false, 2.05f, 0.55f, 0.00121410796f, 0.231032297f, 0.00519322371f},
    {"rgb3x2.png", "bilinear", "mirror", false, 0.0f, 0.0f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "bilinear", "mirror", false, 0.999f, 0.001f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "bilinear", "mirror", true, 0.1f, 0.2f, 0.0392156877f, 0.784313798f, 0.117647059f},
    {"rgb3x2.png", "bilinear", "mirror", true, 0.5f, 0.5f, 0.990196109f, 0.509803951f, 0.750980377f},
    {"rgb3x2.png", "bilinear", "mirror", true, 0.9f, 0.85f, 0.501960814f, 0.125490203f, 0.0274509806f},
    {"rgb3x2.png", "bilinear", "mirror", true, 1.3f, -0.2f, 0.542745054f, 0.158431411f, 0.800784409f},
    {"rgb3x2.png", "bilinear", "mirror", true, -0.45f, 1.7f, 0.840294063f, 0.205882356f, 0.484882295f},
    {"rgb3x2.png", "bilinear", "mirror", true, 2.05f, 0.55f, 0.0156862754f, 0.313725501f, 0.0470588244f},
    {"rgb3x2.png", "bilinear", "mirror", true, 0.0f, 0.0f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "bilinear", "mirror", true, 0.999f, 0.001f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "bilinear", "clamp", false, 0.1f, 0.2f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "bilinear", "clamp", false, 0.5f, 0.5f, 0.977986634f, 0.500758827f, 0.607930183f},
    {"rgb3x2.png", "bilinear", "clamp", false, 0.9f, 0.85f, 0.215860412f, 0.0144438688f, 0.00212468905f},
    {"rgb3x2.png", "bilinear", "clamp", false, 1.3f, -0.2f, 0.0512694456f, 0.0512694456f, 1.0f},
    {"rgb3x2.png", "bilinear", "clamp", false, -0.45f, 1.7f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "bilinear", "clamp", false, 2.05f, 0.55f, 0.150024027f, 0.0291740987f, 0.40127477f},
    {"rgb3x2.png", "bilinear", "clamp", false, 0.0f, 0.0f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "bilinear", "clamp", false, 0.999f, 0.001f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "bilinear", "clamp", true, 0.1f, 0.2f, 0.0392156877f, 0.784313798f, 0.117647059f},
    {"rgb3x2.png", "bilinear", "clamp", true, 0.5f, 0.5f, 0.990196109f, 0.509803951f, 0.750980377f},
    {"rgb3x2.png", "bilinear", "clamp", true, 0.9f, 0.85f, 0.501960814f, 0.125490203f, 0.0274509806f},
    {"rgb3x2.png", "bilinear", "clamp", true, 1.3f, -0.2f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "bilinear", "clamp", true, -0.45f, 1.7f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "bilinear", "clamp", true, 2.05f, 0.55f, 0.401568651f, 0.175686285f, 0.416470587f},
    {"rgb3x2.png", "bilinear", "clamp", true, 0.0f, 0.0f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "bilinear", "clamp", true, 0.999f, 0.001f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", false, 0.1f, 0.2f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "repeat", false, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", false, 0.9f, 0.85f, 0.215860412f, 0.0144438697f, 0.00212468905f},
    {"rgb3x2.png", "nearest", "repeat", false, 1.3f, -0.2f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "repeat", false, -0.45f, 1.7f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", false, 2.05f, 0.55f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "repeat", false, 0.0f, 0.0f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "repeat", false, 0.999f, 0.001f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", true, 0.1f, 0.2f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "repeat", true, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", true, 0.9f, 0.85f, 0.501960814f, 0.125490203f, 0.0274509825f},
    {"rgb3x2.png", "nearest", "repeat", true, 1.3f, -0.2f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "repeat", true, -0.45f, 1.7f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "repeat", true, 2.05f, 0.55f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "repeat", true, 0.0f, 0.0f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "repeat", true, 0.999f, 0.001f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", false, 0.1f, 0.2f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "mirror", false, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", false, 0.9f, 0.85f, 0.215860412f, 0.0144438697f, 0.00212468905f},
    {"rgb3x2.png", "nearest", "mirror", false, 1.3f, -0.2f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", false, -0.45f, 1.7f, 0.955973268f, 0.00151763496f, 0.215860412f},
    {"rgb3x2.png", "nearest", "mirror", false, 2.05f, 0.55f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "mirror", false, 0.0f, 0.0f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "mirror", false, 0.999f, 0.001f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", true, 0.1f, 0.2f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "mirror", true, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", true, 0.9f, 0.85f, 0.501960814f, 0.125490203f, 0.0274509825f},
    {"rgb3x2.png", "nearest", "mirror", true, 1.3f, -0.2f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "nearest", "mirror", true, -0.45f, 1.7f, 0.980392218f, 0.0196078438f, 0.501960814f},
    {"rgb3x2.png", "nearest", "mirror", true, 2.05f, 0.55f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "mirror", true, 0.0f, 0.0f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "mirror", true, 0.999f, 0.001f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", false, 0.1f, 0.2f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "clamp", false, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", false, 0.9f, 0.85f, 0.215860412f, 0.0144438697f, 0.00212468905f},
    {"rgb3x2.png", "nearest", "clamp", false, 1.3f, -0.2f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", false, -0.45f, 1.7f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "clamp", false, 2.05f, 0.55f, 0.215860412f, 0.0144438697f, 0.00212468905f},
    {"rgb3x2.png", "nearest", "clamp", false, 0.0f, 0.0f, 0.00303526991f, 0.57758075f, 0.0129830595f},
    {"rgb3x2.png", "nearest", "clamp", false, 0.999f, 0.001f, 0.0512694418f, 0.0512694418f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", true, 0.1f, 0.2f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "clamp", true, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", true, 0.9f, 0.85f, 0.501960814f, 0.125490203f, 0.0274509825f},
    {"rgb3x2.png", "nearest", "clamp", true, 1.3f, -0.2f, 0.250980407f, 0.250980407f, 1.0f},
    {"rgb3x2.png", "nearest", "clamp", true, -0.45f, 1.7f, 0.0f, 0.0f, 0.0f},
    {"rgb3x2.png", "nearest", "clamp", true, 2.05f, 0.55f, 0.501960814f, 0.125490203f, 0.0274509825f},
    {"rgb3x2.png", "nearest", "clamp", true, 0.0f, 0.0f, 0.0392156877f, 0.784313798f, 0.117647067f},
    {"rgb3x2.png", "nearest", "clamp", true, 0.999f, 0.001f, 0.250980407f, 0.250980407f, 1.0f},
    {"grey2x2.png", "bilinear", "repeat", false, 0.1f, 0.2f, 0.21534729f, 0.21534729f, 0.21534729f},
    {"grey2x2.png", "bilinear", "repeat", false, 0.5f, 0.5f, 0.294115841f, 0.294115841f, 0.294115841f},
    {"grey2x2.png", "bilinear", "repeat", false, 0.9f, 0.85f, 0.32201311f, 0.32201311f, 0.32201311f},
    {"grey2x2.png", "bilinear", "repeat", false, 1.3f, -0.2f, 0.122240297f, 0.122240297f, 0.122240297f},
    {"grey2x2.png", "bilinear", "repeat", false, -0.45f, 1.7f, 0.269856036f, 0.269856036f, 0.269856036f},
    {"grey2x2.png", "bilinear", "repeat", false, 2.05f, 0.55f, 0.237364769f, 0.237364769f, 0.237364769f},
    {"grey2x2.png", "bilinear", "repeat", false, 0.0f, 0.0f, 0.294115841f, 0.294115841f, 0.294115841f},
    {"grey2x2.png", "bilinear", "repeat", false, 0.999f, 0.001f, 0.295344561f, 0.295344561f, 0.295344561f},
    {"grey2x2.png", "bilinear", "repeat", true, 0.1f, 0.2f, 0.325882405f, 0.325882405f, 0.325882405f},
    {"grey2x2.png", "bilinear", "repeat", true, 0.5f, 0.5f, 0.480392158f, 0.480392158f, 0.480392158f},
    {"grey2x2.png", "bilinear", "repeat", true, 0.9f, 0.85f, 0.561568677f, 0.561568677f, 0.561568677f},
    {"grey2x2.png", "bilinear", "repeat", true, 1.3f, -0.2f, 0.3580392f, 0.3580392f, 0.3580392f},
    {"grey2x2.png", "bilinear", "repeat", true, -0.45f, 1.7f, 0.520784318f, 0.520784318f, 0.520784318f},
    {"grey2x2.png", "bilinear", "repeat", true, 2.05f, 0.55f, 0.434509844f, 0.434509844f, 0.434509844f},
    {"grey2x2.png", "bilinear", "repeat", true, 0.0f, 0.0f, 0.480392188f, 0.480392188f, 0.480392188f},
    {"grey2x2.png", "bilinear", "repeat", true, 0.999f, 0.001f, 0.481413841f, 0.481413841f, 0.481413841f},
    {"grey2x2.png", "bilinear", "mirror", false, 0.1f, 0.2f, 0.00699539948f, 0.00699539948f, 0.00699539948f},
    {"grey2x2.png", "bilinear", "mirror", false, 0.5f, 0.5f, 0.294115841f, 0.294115841f, 0.294115841f},
    {"grey2x2.png", "bilinear", "mirror", false, 0.9f, 0.85f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "bilinear", "mirror", false, 1.3f, -0.2f, 0.644823909f, 0.644823909f, 0.644823909f},
    {"grey2x2.png", "bilinear", "mirror", false, -0.45f, 1.7f, 0.281623006f, 0.281623006f, 0.281623006f},
    {"grey2x2.png", "bilinear", "mirror", false, 2.05f, 0.55f, 0.0641432479f, 0.0641432479f, 0.0641432479f},
    {"grey2x2.png", "bilinear", "mirror", false, 0.0f, 0.0f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "bilinear", "mirror", false, 0.999f, 0.001f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "bilinear", "mirror", true, 0.1f, 0.2f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "bilinear", "mirror", true, 0.5f, 0.5f, 0.480392158f, 0.480392158f, 0.480392158f},
    {"grey2x2.png", "bilinear", "mirror", true, 0.9f, 0.85f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "bilinear", "mirror", true, 1.3f, -0.2f, 0.784313858f, 0.784313858f, 0.784313858f},
    {"grey2x2.png", "bilinear", "mirror", true, -0.45f, 1.7f, 0.399215698f, 0.399215698f, 0.399215698f},
    {"grey2x2.png", "bilinear", "mirror", true, 2.05f, 0.55f, 0.24313727f, 0.24313727f, 0.24313727f},
    {"grey2x2.png", "bilinear", "mirror", true, 0.0f, 0.0f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "bilinear", "mirror", true, 0.999f, 0.001f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "bilinear", "clamp", false, 0.1f, 0.2f, 0.00699539948f, 0.00699539948f, 0.00699539948f},
    {"grey2x2.png", "bilinear", "clamp", false, 0.5f, 0.5f, 0.294115841f, 0.294115841f, 0.294115841f},
    {"grey2x2.png", "bilinear", "clamp", false, 0.9f, 0.85f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "bilinear", "clamp", false, 1.3f, -0.2f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "bilinear", "clamp", false, -0.45f, 1.7f, 0.102241814f, 0.102241814f, 0.102241814f},
    {"grey2x2.png", "bilinear", "clamp", false, 2.05f, 0.55f, 0.497196943f, 0.497196943f, 0.497196943f},
    {"grey2x2.png", "bilinear", "clamp", false, 0.0f, 0.0f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "bilinear", "clamp", false, 0.999f, 0.001f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "bilinear", "clamp", true, 0.1f, 0.2f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "bilinear", "clamp", true, 0.5f, 0.5f, 0.480392158f, 0.480392158f, 0.480392158f},
    {"grey2x2.png", "bilinear", "clamp", true, 0.9f, 0.85f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "bilinear", "clamp", true, 1.3f, -0.2f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "bilinear", "clamp", true, -0.45f, 1.7f, 0.352941185f, 0.352941185f, 0.352941185f},
    {"grey2x2.png", "bilinear", "clamp", true, 2.05f, 0.55f, 0.721568644f, 0.721568644f, 0.721568644f},
    {"grey2x2.png", "bilinear", "clamp", true, 0.0f, 0.0f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "bilinear", "clamp", true, 0.999f, 0.001f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "nearest", "repeat", false, 0.1f, 0.2f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "repeat", false, 0.5f, 0.5f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "repeat", false, 0.9f, 0.85f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "repeat", false, 1.3f, -0.2f, 0.102241814f, 0.102241814f, 0.102241814f},
    {"grey2x2.png", "nearest", "repeat", false, -0.45f, 1.7f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "repeat", false, 2.05f, 0.55f, 0.102241814f, 0.102241814f, 0.102241814f},
    {"grey2x2.png", "nearest", "repeat", false, 0.0f, 0.0f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "repeat", false, 0.999f, 0.001f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "nearest", "repeat", true, 0.1f, 0.2f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "repeat", true, 0.5f, 0.5f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "repeat", true, 0.9f, 0.85f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "repeat", true, 1.3f, -0.2f, 0.352941185f, 0.352941185f, 0.352941185f},
    {"grey2x2.png", "nearest", "repeat", true, -0.45f, 1.7f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "repeat", true, 2.05f, 0.55f, 0.352941185f, 0.352941185f, 0.352941185f},
    {"grey2x2.png", "nearest", "repeat", true, 0.0f, 0.0f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "repeat", true, 0.999f, 0.001f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "nearest", "mirror", false, 0.1f, 0.2f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "mirror", false, 0.5f, 0.5f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "mirror", false, 0.9f, 0.85f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "mirror", false, 1.3f, -0.2f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "nearest", "mirror", false, -0.45f, 1.7f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "mirror", false, 2.05f, 0.55f, 0.102241814f, 0.102241814f, 0.102241814f},
    {"grey2x2.png", "nearest", "mirror", false, 0.0f, 0.0f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "mirror", false, 0.999f, 0.001f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "nearest", "mirror", true, 0.1f, 0.2f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "mirror", true, 0.5f, 0.5f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "mirror", true, 0.9f, 0.85f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "mirror", true, 1.3f, -0.2f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "nearest", "mirror", true, -0.45f, 1.7f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "mirror", true, 2.05f, 0.55f, 0.352941185f, 0.352941185f, 0.352941185f},
    {"grey2x2.png", "nearest", "mirror", true, 0.0f, 0.0f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "mirror", true, 0.999f, 0.001f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "nearest", "clamp", false, 0.1f, 0.2f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "clamp", false, 0.5f, 0.5f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "clamp", false, 0.9f, 0.85f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "clamp", false, 1.3f, -0.2f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "nearest", "clamp", false, -0.45f, 1.7f, 0.102241814f, 0.102241814f, 0.102241814f},
    {"grey2x2.png", "nearest", "clamp", false, 2.05f, 0.55f, 0.351532549f, 0.351532549f, 0.351532549f},
    {"grey2x2.png", "nearest", "clamp", false, 0.0f, 0.0f, 0.00699539902f, 0.00699539902f, 0.00699539902f},
    {"grey2x2.png", "nearest", "clamp", false, 0.999f, 0.001f, 0.715693593f, 0.715693593f, 0.715693593f},
    {"grey2x2.png", "nearest", "clamp", true, 0.1f, 0.2f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "clamp", true, 0.5f, 0.5f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "clamp", true, 0.9f, 0.85f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "clamp", true, 1.3f, -0.2f, 0.862745166f, 0.862745166f, 0.862745166f},
    {"grey2x2.png", "nearest", "clamp", true, -0.45f, 1.7f, 0.352941185f, 0.352941185f, 0.352941185f},
    {"grey2x2.png", "nearest", "clamp", true, 2.05f, 0.55f, 0.627451003f, 0.627451003f, 0.627451003f},
    {"grey2x2.png", "nearest", "clamp", true, 0.0f, 0.0f, 0.0784313753f, 0.0784313753f, 0.0784313753f},
    {"grey2x2.png", "nearest", "clamp", true, 0.999f, 0.001f, 0.862745166f, 0.862745166f, 0.862745166f},
};

struct CheckerCase {
    float u, v, r, g, b;
};

// checkerboard color0 (0.9, 0.1, 0.2), color1 (0.05, 0.6, 0.3), to_uv scale 4 3 1
const CheckerCase kChecker[] = {
    {0.1f, 0.2f, 0.0500000007f, 0.600000024f, 0.300000012f},
    {0.5f, 0.5f, 0.899999976f, 0.100000001f, 0.200000003f},
    {0.9f, 0.85f, 0.899999976f, 0.100000001f, 0.200000003f},
    {1.3f, -0.2f, 0.899999976f, 0.100000001f, 0.200000003f},
    {-0.45f, 1.7f, 0.899999976f, 0.100000001f, 0.200000003f},
    {2.05f, 0.55f, 0.0500000007f, 0.600000024f, 0.300000012f},
    {0.0f, 0.0f, 0.899999976f, 0.100000001f, 0.200000003f},
    {0.999f, 0.001f, 0.0500000007f, 0.600000024f, 0.300000012f},
};

std::string data_file(const char* name) { return std::string(CANDELA_TEST_DATA) + "/textures/" + name; }

void expect_close(vec3 got, vec3 want, const std::string& what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c], want[c], 2e-6f + 2e-6f * std::abs(want[c])) << what << " channel " << c;
}

}  // namespace

TEST(Texture, BitmapMatchesMitsuba) {
    int n = 0;
    for (const BitmapCase& c : kBitmap) {
        BitmapTexture t;
        t.texels = load_texels(data_file(c.file), c.raw);
        t.filter = std::strcmp(c.filter, "nearest") == 0 ? TextureFilter::Nearest : TextureFilter::Bilinear;
        t.wrap = std::strcmp(c.wrap, "mirror") == 0  ? TextureWrap::Mirror
                 : std::strcmp(c.wrap, "clamp") == 0 ? TextureWrap::Clamp
                                                     : TextureWrap::Repeat;
        TextureQuery q;
        q.uv = vec2(c.u, c.v);
        expect_close(t.eval(q), vec3(c.r, c.g, c.b),
                     std::string(c.file) + " " + c.filter + " " + c.wrap + (c.raw ? " raw" : "") + " at (" +
                         std::to_string(c.u) + ", " + std::to_string(c.v) + ")");
        ++n;
    }
    EXPECT_EQ(n, 2 * 2 * 3 * 2 * 8);
}

TEST(Texture, CheckerboardMatchesMitsuba) {
    CheckerboardTexture t;
    t.color0 = std::make_shared<Texture>(constant_texture(vec3(0.9f, 0.1f, 0.2f)));
    t.color1 = std::make_shared<Texture>(constant_texture(vec3(0.05f, 0.6f, 0.3f)));
    t.to_uv = UvTransform::from_mat4(glm::scale(mat4(1.f), vec3(4.f, 3.f, 1.f)));
    for (const CheckerCase& c : kChecker) {
        TextureQuery q;
        q.uv = vec2(c.u, c.v);
        expect_close(t.eval(q), vec3(c.r, c.g, c.b), "checkerboard at (" + std::to_string(c.u) + ", " + std::to_string(c.v) + ")");
    }
}

TEST(Texture, UvTransformTakesTheAffinePartOfA4x4) {
    mat4 m = glm::translate(mat4(1.f), vec3(0.25f, -0.5f, 7.f)) * glm::scale(mat4(1.f), vec3(2.f, 3.f, 5.f));
    vec2 uv = UvTransform::from_mat4(m).apply(vec2(0.5f, 0.25f));
    EXPECT_FLOAT_EQ(uv.x, 2.f * 0.5f + 0.25f);
    EXPECT_FLOAT_EQ(uv.y, 3.f * 0.25f - 0.5f);
}

TEST(Texture, MeshAttributeReadsTheVertexColour) {
    Texture t{MeshAttributeTexture{}};
    TextureQuery q;
    q.vertex_color = vec3(0.1f, 0.2f, 0.3f);
    EXPECT_EQ(t.eval(q), q.vertex_color);
    EXPECT_TRUE(t.uses_vertex_colors());
    EXPECT_FALSE(constant_texture(vec3(1.f)).uses_vertex_colors());
    EXPECT_NEAR(t.eval_1(q), luminance(q.vertex_color), 1e-7f);
}

namespace {

// Loading `path` throws one line naming the file and containing `what`.
void expect_texels_error(const std::string& path, const char* what) {
    try {
        load_texels(path, false);
        ADD_FAILURE() << path << " was accepted";
    } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(path), std::string::npos) << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
    }
}

}  // namespace

TEST(Texture, BadImageFilesAreCleanErrors) {
    const std::string dir = candela::test::temp_dir("texture_bad");
    expect_texels_error(dir + "/missing.png", "not found");
    candela::test::write_text(dir + "/garbage.png", "this is not an image at all");
    expect_texels_error(dir + "/garbage.png", "cannot read image");
    // A PNG whose header claims 100000 x 100000 pixels (40 GB as floats).
    const unsigned char header[] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                    0, 0x01, 0x86, 0xa0, 0, 0x01, 0x86, 0xa0, 8, 2, 0, 0, 0, 0, 0, 0, 0};
    std::ofstream(dir + "/huge.png", std::ios::binary).write(reinterpret_cast<const char*>(header), sizeof header);
    expect_texels_error(dir + "/huge.png", "huge.png");
    // A truncated copy of a good PNG.
    std::string good = candela::test::read_bytes(data_file("rgb3x2.png"));
    candela::test::write_text(dir + "/truncated.png", good.substr(0, good.size() / 2));
    expect_texels_error(dir + "/truncated.png", "truncated.png");
    // Fuzzer findings against Debian 12's stb_image JPEG decoder, now refused by libjpeg-turbo or
    // before decoding: Huffman code counts summing to more than 256 (stb wrote past its table), a
    // scan using an undefined table (an undefined shift in stb), and 836 bytes claiming 16386 x
    // 6400 texels (stb decoded 105 megatexels of zeros: 45 s and 1.9 GB under ASan).
    expect_texels_error(data_file("bad_huffman.jpg"), "Bogus Huffman table");
    expect_texels_error(data_file("undefined_huffman.jpg"), "Huffman table 0x02 was not defined");
    expect_texels_error(data_file("claims_16386x6400.jpg"), "JPEG claims 16386x6400 texels, more than its 836 bytes");
    // The same for the formats stb_image still reads: a BMP header claiming 10000 x 10000 texels.
    std::string bmp = "BM" + std::string(52, '\0');
    auto put32 = [&](size_t at, uint32_t v) { for (int k = 0; k < 4; ++k) bmp[at + size_t(k)] = char(v >> (8 * k)); };
    put32(10, 54), put32(14, 40), put32(18, 10000), put32(22, 10000);
    bmp[26] = 1, bmp[28] = 24;
    candela::test::write_text(dir + "/huge.bmp", bmp);
    expect_texels_error(dir + "/huge.bmp", "image claims 10000x10000 texels, more than its 54 bytes");
    // PGM/PPM headers (found by fuzz_image: stb_image's parser overflowed a signed int on a long
    // number); binary PNM is read by decode_pnm now.
    candela::test::write_text(dir + "/long.pgm", "P5 54 6227103515 4  \xcc");
    expect_texels_error(dir + "/long.pgm", "bad PNM header: height above 1048576");
    candela::test::write_text(dir + "/short.ppm", "P6 4 4 255\n" + std::string(47, 'x'));
    expect_texels_error(dir + "/short.ppm", "truncated PNM: 47 bytes of raster, expected 48");
    candela::test::write_text(dir + "/nomax.ppm", "P6 4 4 # no maxval\n");
    expect_texels_error(dir + "/nomax.ppm", "bad PNM header: no maxval");
    candela::test::write_text(dir + "/anim.gif", std::string("GIF89a") + std::string(40, '\0'));
    expect_texels_error(dir + "/anim.gif", "unsupported image format");
    auto jpg = load_texels(data_file("rgb2x2.jpg"), false);
    EXPECT_EQ(jpg->width, 2);
    EXPECT_EQ(jpg->height, 2);
    EXPECT_EQ(jpg->channels, 3);
    // A 2 x 2 PIZ-compressed EXR whose chunk is whole but does not decode (found by fuzz_image:
    // tinyexr 1.0.1 leaked its channel buffers there; the sanitizer build's leak checker sees it).
    expect_texels_error(data_file("bad_piz.exr"), "cannot decode EXR pixels");
}

// A JPEG written by libjpeg here (64 x 48, colour gradients, quality 100, no chroma subsampling),
// baseline, progressive and arithmetic-coded, decodes to its source texels within the codec's error, the right way
// up and in RGB order; cut short, it is a one-line error rather than a grey-filled image.
namespace {

// A JPEG of `src` (RGB, 8 bits, rows from the top) written by libjpeg: quality 100, no chroma
// subsampling; progressive or arithmetic-coded on request.
std::string encode_jpeg(const std::vector<uint8_t>& src, int w, int h, bool progressive, bool arith) {
    jpeg_compress_struct c;
    jpeg_error_mgr err;
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    unsigned char* out = nullptr;
    unsigned long size = 0;
    jpeg_mem_dest(&c, &out, &size);
    c.image_width = JDIMENSION(w), c.image_height = JDIMENSION(h), c.input_components = 3, c.in_color_space = JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 100, TRUE);
    for (int k = 0; k < 3; ++k) c.comp_info[k].h_samp_factor = c.comp_info[k].v_samp_factor = 1;
    if (progressive) jpeg_simple_progression(&c);
    c.arith_code = arith;
    jpeg_start_compress(&c, TRUE);
    while (c.next_scanline < c.image_height) {
        JSAMPROW row = const_cast<uint8_t*>(&src[size_t(c.next_scanline) * size_t(w) * 3]);
        jpeg_write_scanlines(&c, &row, 1);
    }
    jpeg_finish_compress(&c);
    const std::string bytes(reinterpret_cast<const char*>(out), size);
    jpeg_destroy_compress(&c);
    std::free(out);
    return bytes;
}

}  // namespace

TEST(Texture, JpegDecodesAndTruncatedJpegIsAnError) {
    const std::string dir = candela::test::temp_dir("texture_jpeg");
    const int w = 64, h = 48;
    std::vector<uint8_t> src(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            uint8_t* p = &src[3 * (size_t(y) * w + x)];
            p[0] = uint8_t(4 * x), p[1] = uint8_t(5 * y), p[2] = uint8_t(200 - 2 * x);
        }
    // Baseline, progressive, and arithmetic-coded (libjpeg-turbo reads and writes it).
    const char* name[3] = {"baseline", "progressive", "arithmetic"};
    for (int kind = 0; kind < 3; ++kind) {
        const std::string bytes = encode_jpeg(src, w, h, kind == 1, kind == 2);
        const std::string path = dir + "/" + name[kind] + ".jpg";
        candela::test::write_text(path, bytes);
        auto g = load_texels(path, true);
        ASSERT_EQ(g->width, w);
        ASSERT_EQ(g->height, h);
        ASSERT_EQ(g->channels, 3);
        float worst = 0.f;
        for (size_t i = 0; i < src.size(); ++i) worst = std::max(worst, std::abs(g->data[i] * 255.f - float(src[i])));
        EXPECT_LE(worst, 3.f) << path;  // quality 100: a few levels at most
        auto lin = load_texels(path, false);  // sRGB-decoded unless raw
        EXPECT_NEAR(lin->data[3 * 10 + 1], srgb_to_linear(g->data[3 * 10 + 1]), 1e-6f);

        const std::string cut = dir + "/" + name[kind] + "_cut.jpg";
        candela::test::write_text(cut, bytes.substr(0, bytes.size() * 2 / 3));
        expect_texels_error(cut, "Premature end of JPEG file");
    }
    // A flat 1024 x 1024 image, arithmetic-coded, takes far less than a bit a block: the bound of
    // 512 texels a byte (Huffman files) must not refuse it.
    const std::vector<uint8_t> flat(size_t(1024) * 1024 * 3, 100);
    const std::string small = encode_jpeg(flat, 1024, 1024, false, true);
    EXPECT_GT(1024.0 * 1024.0, 512.0 * double(small.size())) << "the file is not small enough to test the bound";
    candela::test::write_text(dir + "/flat_arithmetic.jpg", small);
    auto f = load_texels(dir + "/flat_arithmetic.jpg", true);
    EXPECT_EQ(f->width, 1024);
    EXPECT_NEAR(f->data[3 * 1000 + 2], 100.f / 255.f, 1e-6f);
}

// Binary PGM and PPM: comments in the header, 8 and 16 bits (big-endian), values over maxval,
// rows from the top; decoded from sRGB unless raw, like the other 8/16-bit formats.
TEST(Texture, PnmDecodes) {
    const std::string dir = candela::test::temp_dir("texture_pnm");
    // 2 x 1 colour, maxval 255: (255, 0, 51) and (0, 102, 255).
    candela::test::write_text(dir + "/a.ppm", std::string("P6\n# made by hand\n2 1\n255\n") + std::string("\xff\x00\x33\x00\x66\xff", 6));
    auto c = load_texels(dir + "/a.ppm", true);
    ASSERT_EQ(c->width, 2);
    ASSERT_EQ(c->height, 1);
    ASSERT_EQ(c->channels, 3);
    const float want[6] = {1.f, 0.f, 0.2f, 0.f, 0.4f, 1.f};
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(c->data[size_t(i)], want[i], 1e-6f) << i;
    auto lin = load_texels(dir + "/a.ppm", false);
    EXPECT_NEAR(lin->data[2], srgb_to_linear(0.2f), 1e-6f);
    // 1 x 2 grey, maxval 1000 (two bytes a sample): 500 on top, 1000 below.
    candela::test::write_text(dir + "/b.pgm", std::string("P5 1 2 1000\n") + std::string("\x01\xf4\x03\xe8", 4));
    auto g = load_texels(dir + "/b.pgm", true);
    ASSERT_EQ(g->width, 1);
    ASSERT_EQ(g->height, 2);
    ASSERT_EQ(g->channels, 1);
    EXPECT_NEAR(g->data[0], 0.5f, 1e-6f);
    EXPECT_NEAR(g->data[1], 1.f, 1e-6f);
}

// Radiance RGBE, flat and run-length coded (8 x 2: runs and literals in each channel), to the same
// linear texels, mantissa * 2^(e - 136) as Mitsuba converts; a run-length scanline cut short or a
// zero-length run is an error (Debian 12's stb_image looped forever on the first).
TEST(Texture, RgbeDecodesFlatAndRunLength) {
    const std::string dir = candela::test::temp_dir("texture_rgbe");
    const int w = 8, h = 2;
    auto texel = [](int x, int y, int c) { return c == 3 ? uint8_t(128 + y) : uint8_t(c == 0 ? 200 : c == 1 ? 16 * x : 7); };
    const std::string header = "#?RADIANCE\n# a comment\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1\n\n-Y 2 +X 8\n";
    std::string flat = header, rle = header;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) flat += char(texel(x, y, c));
        rle += std::string("\x02\x02\x00\x08", 4);
        for (int c = 0; c < 4; ++c) {
            if (c == 1) {  // a literal of all 8 values
                rle += char(8);
                for (int x = 0; x < w; ++x) rle += char(texel(x, y, c));
            } else {  // a run of 5 and a run of 3
                rle += char(128 + 5), rle += char(texel(0, y, c)), rle += char(128 + 3), rle += char(texel(0, y, c));
            }
        }
    }
    candela::test::write_text(dir + "/flat.hdr", flat);
    candela::test::write_text(dir + "/rle.hdr", rle);
    auto a = load_texels(dir + "/flat.hdr", false), b = load_texels(dir + "/rle.hdr", false);
    ASSERT_EQ(a->width, w);
    ASSERT_EQ(a->height, h);
    ASSERT_EQ(b->width, w);
    ASSERT_EQ(b->height, h);
    EXPECT_EQ(a->data, b->data);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(a->data[3 * size_t(y * w + x) + size_t(c)], std::ldexp(float(texel(x, y, c)), 128 + y - 136));

    candela::test::write_text(dir + "/cut.hdr", header + std::string("\x02\x02\x00\x08", 4));
    expect_texels_error(dir + "/cut.hdr", "truncated Radiance HDR pixel data");
    candela::test::write_text(dir + "/zero_run.hdr", header + std::string("\x02\x02\x00\x08\x00\x00\x00\x00", 8));
    expect_texels_error(dir + "/zero_run.hdr", "bad run in scanline 0");
    candela::test::write_text(dir + "/xyz.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 2 +X 8\n");
    expect_texels_error(dir + "/xyz.hdr", "unsupported Radiance HDR FORMAT=32-bit_rle_xyze");
    candela::test::write_text(dir + "/flipped.hdr", "#?RADIANCE\n\n+Y 2 +X 8\n");
    expect_texels_error(dir + "/flipped.hdr", "resolution line");
}

// ---- textured materials in a render, against Mitsuba -------------------------------------------
// tests/data/scenes/textured.xml (a checkerboard floor, a nearest-filtered bitmap wall, a smooth
// plastic cube with a bilinear bitmap) against the mean of 16 Mitsuba 3.9.1 renders of 1024 spp
// at 48 x 48 and the variance of that mean, made by
//   $PY tests/data/make_reference.py tests/data/scenes/textured.xml --res 48 --batches 16 --spp 1024
//       --out tests/data/textured48
// candela renders 8 batches of 128 spp; block z-test on 8 x 8 blocks (Sidak over blocks and
// channels). Control: the checkerboard's colours swapped must fail.

namespace {

candela::stats::ImageEstimate load_textured_reference() {
    return candela::stats::ImageEstimate::from_reference_files(std::string(CANDELA_TEST_DATA) + "/textured48");
}

candela::stats::ImageEstimate render_textured(const std::vector<std::pair<std::string, std::string>>& defines) {
    auto d = defines;
    d.push_back({"res", "48"});
    auto built = build_scene(load_scene(std::string(CANDELA_TEST_DATA) + "/scenes/textured.xml", d));
    return candela::test::render_batch_estimate(*built, built->params(), 8, 128);
}

}  // namespace

TEST(Texture, MitsubaAgreementRender) {
    using namespace candela::stats;
    ImageEstimate ref = load_textured_reference();
    ASSERT_EQ(ref.width, 48);
    BlockTestResult r = block_z_test(render_textured({}), ref, 8, 0.01);
    std::printf("  textured scene: %s\n", r.describe().c_str());
    EXPECT_TRUE(r.passed(0.01)) << r.describe();
}

TEST(Texture, MitsubaAgreementDetectsSwappedCheckerColours) {
    using namespace candela::stats;
    ImageEstimate ref = load_textured_reference();
    BlockTestResult r = block_z_test(render_textured({{"color0", "0.1, 0.7, 0.2"}, {"color1", "0.8, 0.1, 0.1"}}), ref, 8, 0.01);
    std::printf("  checker colours swapped: %s\n", r.describe().c_str());
    EXPECT_FALSE(r.passed(0.01)) << r.describe();
}

// A texture for a parameter candela does not texture, or a value and a texture for one parameter,
// are errors at the texture's line.
TEST(Texture, UnsupportedTextureParametersAreErrors) {
    const std::string dir = candela::test::temp_dir("texture_params");
    auto expect_error = [&](const std::string& bsdf, const std::string& what) {
        const std::string path = dir + "/s.xml";
        candela::test::write_text(path, "<scene version=\"3.0.0\">\n<shape type=\"rectangle\">\n" + bsdf +
                                            "</shape>\n<shape type=\"rectangle\"><emitter type=\"area\"/></shape>\n</scene>\n");
        try {
            build_scene(load_scene(path));
            ADD_FAILURE() << bsdf << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(path + ":"), std::string::npos) << e.what();
        }
    };
    // Mitsuba's roughplastic keeps a scalar roughness (its coat tables depend on it).
    expect_error("<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"ggx\"/>\n"
                 "<texture type=\"checkerboard\" name=\"alpha\"/></bsdf>\n",
                 "a texture for 'alpha' is not supported");
    expect_error("<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5\"/>\n"
                 "<texture type=\"checkerboard\" name=\"reflectance\"/></bsdf>\n",
                 "both as a value and as a texture");
    expect_error("<bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\">\n"
                 "<string name=\"filename\" value=\"nope.png\"/></texture></bsdf>\n",
                 "texture file not found");
    expect_error("<bsdf type=\"diffuse\"><texture type=\"mesh_attribute\" name=\"reflectance\">\n"
                 "<string name=\"name\" value=\"face_color\"/></texture></bsdf>\n",
                 "not supported (only vertex_color)");
}

// Mitsuba's constant spectra as textures (srgb, d65, uniform, rawconstant) give the colours Mitsuba
// 3.9.1's scalar_rgb evaluates them to (srgb and d65: their colour, d65 times its scale, uniform and
// rawconstant: their value), folded into the BSDF's or emitter's value: nothing stays textured.
TEST(Texture, ConstantSpectraFoldIntoValues) {
    auto albedo = [](const std::string& tex) {
        const Material m = test::load_bsdf_material("texture-constants", "c",
                                                    "<bsdf type=\"diffuse\">" + tex + "</bsdf>");
        EXPECT_FALSE(m.textured());
        return std::get<DiffuseBsdf>(m.bsdf).albedo;
    };
    EXPECT_EQ(albedo("<texture type=\"srgb\" name=\"reflectance\"><rgb name=\"color\" value=\"0.5, 0.2, 0.1\"/></texture>"),
              vec3(0.5f, 0.2f, 0.1f));
    EXPECT_EQ(albedo("<texture type=\"d65\" name=\"reflectance\"><rgb name=\"color\" value=\"0.5, 0.2, 0.1\"/>"
                     "<float name=\"scale\" value=\"0.5\"/></texture>"),
              vec3(0.25f, 0.1f, 0.05f));
    EXPECT_EQ(albedo("<texture type=\"uniform\" name=\"reflectance\"><float name=\"value\" value=\"0.25\"/></texture>"),
              vec3(0.25f));
    EXPECT_EQ(albedo("<texture type=\"rawconstant\" name=\"reflectance\"><float name=\"value\" value=\"0.3\"/></texture>"),
              vec3(0.3f));
    // A float parameter takes the constant's value (a roughness here).
    const Material rc = test::load_bsdf_material(
        "texture-constants", "alpha",
        "<bsdf type=\"roughconductor\"><texture type=\"uniform\" name=\"alpha\"><float name=\"value\" value=\"0.3\"/></texture></bsdf>");
    EXPECT_FALSE(rc.textured());
    EXPECT_FLOAT_EQ(std::get<ConductorBsdf>(rc.bsdf).alpha_u, 0.3f);
    // Inside a checkerboard, as one of its colours.
    const Material cb = test::load_bsdf_material(
        "texture-constants", "checker",
        "<bsdf type=\"diffuse\"><texture type=\"checkerboard\" name=\"reflectance\"><texture type=\"srgb\" name=\"color0\">"
        "<rgb name=\"color\" value=\"0.9, 0.1, 0.1\"/></texture></texture></bsdf>");
    ASSERT_TRUE(cb.textured());
    TextureQuery q;
    q.uv = vec2(0.25f, 0.25f);
    EXPECT_EQ(cb.textures[0].texture->eval(q), vec3(0.9f, 0.1f, 0.1f));
    // Emitters: constant, area and point strengths.
    const std::string d = test::temp_dir("texture-constant-emitters");
    test::write_text(d + "/e.xml",
                     "<scene version=\"3.0.0\">\n<emitter type=\"constant\"><texture type=\"d65\" name=\"radiance\">"
                     "<float name=\"scale\" value=\"0.5\"/></texture></emitter>\n"
                     "<shape type=\"sphere\"><emitter type=\"area\"><texture type=\"srgb\" name=\"radiance\">"
                     "<rgb name=\"color\" value=\"2, 1, 1\"/><boolean name=\"unbounded\" value=\"true\"/></texture></emitter></shape>\n"
                     "</scene>\n");
    const SceneDescription s = load_scene(d + "/e.xml");
    ASSERT_EQ(s.emitters.size(), 1u);
    EXPECT_EQ(s.emitters[0].radiance, vec3(2.f, 1.f, 1.f));
    EXPECT_FALSE(s.emitters[0].texture);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(std::get<ConstantLight>(s.lights[0].model).radiance, vec3(0.5f));
    // Refusals: a reflectance above 1 unless unbounded, a missing colour, a varying texture where
    // only a value is taken.
    EXPECT_NE(test::load_bsdf_error("texture-constants", "bad", "<bsdf type=\"diffuse\">\n<texture type=\"srgb\" "
                                                                "name=\"reflectance\"><rgb name=\"color\" value=\"1.5, 0, 0\"/></texture></bsdf>")
                  .find("must be in [0, 1]"),
              std::string::npos);
    EXPECT_NE(test::load_bsdf_error("texture-constants", "nocolor", "<bsdf type=\"diffuse\">\n<texture type=\"srgb\" "
                                                                    "name=\"reflectance\"/></bsdf>")
                  .find("srgb needs a 'color'"),
              std::string::npos);
    test::write_text(d + "/v.xml", "<scene version=\"3.0.0\">\n<emitter type=\"constant\"><texture type=\"checkerboard\" "
                                   "name=\"radiance\"/></emitter>\n</scene>\n");
    try {
        load_scene(d + "/v.xml");
        ADD_FAILURE() << "a checkerboard radiance on a constant emitter was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("v.xml:2: a varying texture for 'radiance'"), std::string::npos) << e.what();
    }
}
