#version 330 core
// A character's skinned meshes, posed on the GPU (skinning.glsl) and shaded as the head mesh is.

#if defined VERTEX_SHADER

#include "skinning.glsl"

uniform mat4 u_mvp;
uniform mat4 u_view;

in vec3 in_normal;

out vec3 v_normal;   // view space
out vec3 v_to_eye;   // view space, fragment to eye

void main() {
    mat4 skin = skin_matrix();
    vec4 world = skin * vec4(in_position, 1.0);
    gl_Position = u_mvp * world;
    v_normal = (u_view * vec4(mat3(skin) * in_normal, 0.0)).xyz;
    v_to_eye = -(u_view * world).xyz;
}

#elif defined FRAGMENT_SHADER

#include "mesh_fragment.glsl"

#endif
