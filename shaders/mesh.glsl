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

#include "mesh_fragment.glsl"

#endif
