#pragma once
// The display transform, shared by the viewer window and headless PNG output: the film's linear
// RGB goes to a float texture, and the shaders in shaders/ apply exposure (2^stops) and the sRGB
// transfer function. There is one tonemap implementation, in GLSL; C++ never re-implements it.
namespace candela {

struct DisplaySettings {
    float exposure = 0.f;  // stops: the image is multiplied by 2^exposure before encoding
};

}  // namespace candela
