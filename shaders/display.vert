#version 330 core
// One triangle that covers the whole viewport, with no vertex buffer: the corners come from
// gl_VertexID as (-1,-1), (3,-1), (-1,3). A single triangle has no diagonal seam, and clipping
// keeps every fragment inside the viewport, so the caller picks the target rectangle with
// glViewport alone.
//
// v_uv is (0,0) at the top-left of the image and (1,1) at the bottom-right: the image is uploaded
// top row first (texel row 0 = top), so nothing is flipped on the CPU.
out vec2 v_uv;

void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    v_uv = vec2(p.x + 1.0, 1.0 - p.y) * 0.5;
    gl_Position = vec4(p, 0.0, 1.0);
}
