// The fragment stage strands_quads.glsl and strands_thin.glsl share (#include): the colour the
// vertex stage chose, with the ghost's alpha where every vertex is the flat colour.

uniform bool u_use_flat_color;
uniform vec4 u_flat_color;

in vec3 v_color;
out vec4 f_color;

void main() {
    f_color = vec4(v_color, u_use_flat_color ? u_flat_color.a : 1.0);
}
