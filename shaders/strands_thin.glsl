#version 330 core
// Strands, fast path: one plain 1-px LINE_STRIP draw with primitive restart, no geometry stage
// (Mesa's llvmpipe runs geometry shaders slowly). Used for widths up to 1.5 px and whenever the
// artist asks for fast lines. Colour as in strands.glsl: per-vertex, the ramp at t, or flat RGBA.

#if defined VERTEX_SHADER

uniform mat4 u_mvp;             // pyrr row-major view @ proj, written as is
uniform bool u_use_vertex_color;
uniform bool u_use_flat_color;  // ghost: every vertex u_flat_color
uniform vec4 u_flat_color;     // its alpha is the fragments' alpha
uniform sampler2D u_ramp;       // (256 x 1) RGB ramp, root (t = 0) to tip (t = 1)

in vec3 in_position;
in float in_t;
in vec3 in_color;

out vec3 v_color;

void main() {
    gl_Position = u_mvp * vec4(in_position, 1.0);
    vec3 rgb = u_use_vertex_color ? in_color : texture(u_ramp, vec2(clamp(in_t, 0.0, 1.0), 0.5)).rgb;
    v_color = u_use_flat_color ? u_flat_color.rgb : rgb;
}

#elif defined FRAGMENT_SHADER

#include "strands_fragment.glsl"

#endif
