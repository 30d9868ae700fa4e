#version 330 core
// Strands: one LINE_STRIP draw with primitive restart; the geometry stage widens every segment
// into a screen-space quad of u_width pixels, since core-profile contexts (Qt's) refuse
// glLineWidth > 1. Colour: per-vertex, the ramp texture sampled at t = i / (N_s - 1), or one
// flat RGBA (the ghost groom drawn translucent under the strands).

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
out float v_t;

void main() {
    gl_Position = u_mvp * vec4(in_position, 1.0);
    v_t = in_t;
    vec3 rgb = u_use_vertex_color ? in_color : texture(u_ramp, vec2(clamp(in_t, 0.0, 1.0), 0.5)).rgb;
    v_color = u_use_flat_color ? u_flat_color.rgb : rgb;
}

#elif defined GEOMETRY_SHADER

layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;

uniform vec2 u_viewport;        // framebuffer size in pixels
uniform float u_width;          // line width in pixels
uniform float u_taper;          // width × (1 − u_taper · t) at the segment's middle t

in vec3 v_color[];
in float v_t[];
out vec3 g_color;

const float W_MIN = 1e-5;

void main() {
    vec4 a = gl_in[0].gl_Position;
    vec4 b = gl_in[1].gl_Position;
    vec3 ca = v_color[0];
    vec3 cb = v_color[1];
    if (a.w < W_MIN && b.w < W_MIN) return;
    // Clip the segment to the part in front of the eye before dividing by w.
    if (a.w < W_MIN) { float s = (W_MIN - a.w) / (b.w - a.w); a = mix(a, b, s); ca = mix(ca, cb, s); }
    if (b.w < W_MIN) { float s = (W_MIN - b.w) / (a.w - b.w); b = mix(b, a, s); cb = mix(cb, ca, s); }
    vec2 pa = a.xy / a.w * 0.5 * u_viewport;
    vec2 pb = b.xy / b.w * 0.5 * u_viewport;
    vec2 d = pb - pa;
    float len = length(d);
    vec2 dir = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    float h = 0.5 * u_width * (1.0 - u_taper * (0.5 * (v_t[0] + v_t[1])));
    // Half a width past each end, so consecutive segments overlap at the joints.
    vec2 along = dir * h * 2.0 / u_viewport;
    vec2 side = vec2(-dir.y, dir.x) * h * 2.0 / u_viewport;
    g_color = ca;
    gl_Position = vec4(a.xy + (-along + side) * a.w, a.zw); EmitVertex();
    gl_Position = vec4(a.xy + (-along - side) * a.w, a.zw); EmitVertex();
    g_color = cb;
    gl_Position = vec4(b.xy + (along + side) * b.w, b.zw); EmitVertex();
    gl_Position = vec4(b.xy + (along - side) * b.w, b.zw); EmitVertex();
    EndPrimitive();
}

#elif defined FRAGMENT_SHADER

uniform bool u_use_flat_color;
uniform vec4 u_flat_color;

in vec3 g_color;
out vec4 f_color;

void main() {
    f_color = vec4(g_color, u_use_flat_color ? u_flat_color.a : 1.0);
}

#endif
