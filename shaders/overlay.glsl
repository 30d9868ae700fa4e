#version 330 core
// 2-D overlays (the brush circle) given in widget pixels, origin top-left, y down.

#if defined VERTEX_SHADER

uniform vec2 u_viewport_size;   // the size the pixel coordinates refer to

in vec2 in_px;

void main() {
    vec2 ndc = vec2(in_px.x / u_viewport_size.x * 2.0 - 1.0, 1.0 - in_px.y / u_viewport_size.y * 2.0);
    gl_Position = vec4(ndc, 0.0, 1.0);
}

#elif defined FRAGMENT_SHADER

uniform vec4 u_color;
out vec4 f_color;

void main() {
    f_color = u_color;
}

#endif
