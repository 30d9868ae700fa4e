#version 330 core
// Strands as wide lines without a geometry stage: every segment (vertex i to i + 1 of a strand)
// is four vertices of an indexed TRIANGLES draw, 4i … 4i + 3, which read both ends of the
// segment from a texture (vertex pulling: xyz and t in one RGBA32F texel per strand vertex,
// colours in another) and place the corners of the same screen-space quad of u_width pixels as
// strands.glsl's geometry shader makes (half a width past each end, so consecutive segments
// overlap at the joints). Mesa's llvmpipe runs this faster than the geometry shader.

#if defined VERTEX_SHADER

uniform mat4 u_mvp;             // pyrr row-major view @ proj, written as is
uniform vec2 u_viewport;        // framebuffer size in pixels
uniform float u_width;          // line width in pixels
uniform float u_taper;          // width × (1 − u_taper · t) at the segment's middle t
uniform bool u_use_vertex_color;
uniform bool u_use_flat_color;  // ghost: every vertex u_flat_color
uniform vec4 u_flat_color;     // its alpha is the fragments' alpha
uniform sampler2D u_ramp;       // (256 x 1) RGB ramp, root (t = 0) to tip (t = 1)
uniform sampler2D u_points;     // RGBA32F: xyz and t of strand vertex v at (v % width, v / width)
uniform sampler2D u_colors;     // RGB32F: the colour of strand vertex v, same layout

out vec3 v_color;

const float W_MIN = 1e-5;

ivec2 texel(int v, int width) {
    return ivec2(v % width, v / width);
}

vec3 end_color(int v, float t, int width) {
    vec3 rgb = u_use_vertex_color ? texelFetch(u_colors, texel(v, width), 0).rgb
                                  : texture(u_ramp, vec2(clamp(t, 0.0, 1.0), 0.5)).rgb;
    return u_use_flat_color ? u_flat_color.rgb : rgb;
}

void main() {
    int i = gl_VertexID >> 2;
    int k = gl_VertexID & 3;
    int width = textureSize(u_points, 0).x;
    vec4 pa = texelFetch(u_points, texel(i, width), 0);
    vec4 pb = texelFetch(u_points, texel(i + 1, width), 0);
    vec4 a = u_mvp * vec4(pa.xyz, 1.0);
    vec4 b = u_mvp * vec4(pb.xyz, 1.0);
    vec3 ca = end_color(i, pa.w, width);
    vec3 cb = end_color(i + 1, pb.w, width);
    if (a.w < W_MIN && b.w < W_MIN) { gl_Position = vec4(0.0, 0.0, 2.0, 1.0); v_color = ca; return; }
    // Clip the segment to the part in front of the eye before dividing by w.
    if (a.w < W_MIN) { float s = (W_MIN - a.w) / (b.w - a.w); a = mix(a, b, s); ca = mix(ca, cb, s); }
    if (b.w < W_MIN) { float s = (W_MIN - b.w) / (a.w - b.w); b = mix(b, a, s); cb = mix(cb, ca, s); }
    vec2 sa = a.xy / a.w * 0.5 * u_viewport;
    vec2 sb = b.xy / b.w * 0.5 * u_viewport;
    vec2 d = sb - sa;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    float h = 0.5 * u_width * (1.0 - u_taper * (0.5 * (pa.w + pb.w)));
    vec2 along = dir * h * 2.0 / u_viewport;
    vec2 side = vec2(-dir.y, dir.x) * h * 2.0 / u_viewport;
    // Corners in the geometry shader's order: a + side, a − side, b + side, b − side.
    float s = (k == 0 || k == 2) ? 1.0 : -1.0;
    if (k < 2) {
        gl_Position = vec4(a.xy + (-along + s * side) * a.w, a.zw);
        v_color = ca;
    } else {
        gl_Position = vec4(b.xy + (along + s * side) * b.w, b.zw);
        v_color = cb;
    }
}

#elif defined FRAGMENT_SHADER

#include "strands_fragment.glsl"

#endif
