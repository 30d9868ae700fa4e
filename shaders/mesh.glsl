#version 330 core
// A head mesh under the hair: Lambert from a light over the viewer's left shoulder plus a rim
// term, lit in view space. Normals are turned toward the eye, since OBJ heads are not always
// closed or consistently wound (so gl_FrontFacing cannot be trusted).

#if defined VERTEX_SHADER

uniform mat4 u_mvp;
uniform mat4 u_view;

in vec3 in_position;
in vec3 in_normal;

out vec3 v_normal;   // view space
out vec3 v_to_eye;   // view space, fragment to eye

void main() {
    gl_Position = u_mvp * vec4(in_position, 1.0);
    v_normal = (u_view * vec4(in_normal, 0.0)).xyz;
    v_to_eye = -(u_view * vec4(in_position, 1.0)).xyz;
}

#elif defined FRAGMENT_SHADER

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

#endif
