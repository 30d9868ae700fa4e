#version 330 core
// Strands rasterized on the CPU (app/render/soft_raster.py), put into a multisampled frame: one
// full-screen triangle copies their colour and depth, so the head mesh drawn before still hides
// strands behind it. Pixels no strand covers (alpha 0) are left as they are.

#if defined VERTEX_SHADER

void main() {
    // (-1, -1), (3, -1), (-1, 3): one triangle over the whole viewport, no vertex buffer.
    vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0;
    gl_Position = vec4(p, 0.0, 1.0);
}

#elif defined FRAGMENT_SHADER

uniform sampler2D u_color;  // RGBA8, row 0 at the bottom like the framebuffer
uniform sampler2D u_depth;  // R32F window depth in [0, 1]

out vec4 f_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c = texelFetch(u_color, p, 0);
    if (c.a == 0.0) discard;
    f_color = c;
    gl_FragDepth = texelFetch(u_depth, p, 0).r;
}

#endif
