#version 330 core
// The display transform, the only tonemap in candela: linear RGB * 2^exposure, clamped to [0,1],
// then the exact sRGB transfer function. The framebuffer stores the result as is (GL_FRAMEBUFFER_SRGB
// is off while this runs), so an 8-bit target holds sRGB-encoded bytes.
uniform sampler2D u_image;   // linear RGB (GL_RGB32F), texel row 0 = top image row
uniform float u_exposure;    // stops
uniform int u_linear;        // 0: nearest texel, 1: bilinear (for a reduced-resolution preview)

in vec2 v_uv;
out vec4 o_color;

// One texel, made safe before any arithmetic: NaN becomes 0 so that it can neither reach the
// output nor spread to neighbours through filtering, and +-Inf becomes a large finite value so
// that a zero filter weight cannot turn it into NaN (it still saturates to 1 after clamping).
vec3 fetch(ivec2 p) {
    ivec2 size = textureSize(u_image, 0);
    vec3 c = texelFetch(u_image, clamp(p, ivec2(0), size - 1), 0).rgb;
    c = mix(c, vec3(0.0), isnan(c));
    return clamp(c, vec3(-1e30), vec3(1e30));
}

vec3 sample_image(vec2 uv) {
    vec2 size = vec2(textureSize(u_image, 0));
    if (u_linear == 0) return fetch(ivec2(floor(uv * size)));
    // Manual bilinear filtering on sanitised texels (hardware filtering would mix NaN in).
    vec2 pos = uv * size - 0.5;
    vec2 i = floor(pos);
    vec2 f = pos - i;
    ivec2 p = ivec2(i);
    vec3 top = mix(fetch(p), fetch(p + ivec2(1, 0)), f.x);
    vec3 bottom = mix(fetch(p + ivec2(0, 1)), fetch(p + ivec2(1, 1)), f.x);
    return mix(top, bottom, f.y);
}

vec3 srgb_encode(vec3 c) {
    vec3 lo = 12.92 * c;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

void main() {
    vec3 c = clamp(sample_image(v_uv) * exp2(u_exposure), 0.0, 1.0);
    vec3 s = clamp(srgb_encode(c), 0.0, 1.0);
    // Belt and braces: nothing above can make NaN, but a driver's pow() must not either.
    o_color = vec4(mix(s, vec3(0.0), isnan(s)), 1.0);
}
