// The shaded surface of a mesh (the fragment stage mesh.glsl and character.glsl share):
// Lambert from a light over the viewer's left shoulder plus a rim term, lit in view space, the
// normal turned toward the eye (meshes are not always closed or consistently wound).

uniform vec3 u_color;

in vec3 v_normal;
in vec3 v_to_eye;
out vec4 f_color;

const vec3 LIGHT = normalize(vec3(-0.4, 0.6, 0.7));

void main() {
    vec3 n = normalize(v_normal);
    vec3 e = normalize(v_to_eye);
    if (dot(n, e) < 0.0) n = -n;
    float diffuse = max(dot(n, LIGHT), 0.0);
    float rim = pow(1.0 - clamp(dot(n, e), 0.0, 1.0), 3.0);
    f_color = vec4(u_color * (0.25 + 0.75 * diffuse) + vec3(0.35) * rim, 1.0);
}
