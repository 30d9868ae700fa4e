#version 330 core
// An image painted on the CPU over the view (premultiplied alpha, row 0 at the top, the view's
// size), pixel for pixel: one triangle covering the screen.

#if defined VERTEX_SHADER

void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}

#elif defined FRAGMENT_SHADER

uniform sampler2D u_image;
out vec4 f_color;

void main() {
    ivec2 size = textureSize(u_image, 0);
    f_color = texelFetch(u_image, ivec2(gl_FragCoord.x, size.y - 1 - int(gl_FragCoord.y)), 0);
}

#endif
