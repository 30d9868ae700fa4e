#version 330 core
// The skinned positions character.glsl draws, captured by transform feedback (no fragments):
// what the studio's tests compare with the CPU path, vertex by vertex.

#if defined VERTEX_SHADER

#include "skinning.glsl"

out vec3 v_skinned;

void main() {
    v_skinned = (skin_matrix() * vec4(in_position, 1.0)).xyz;
}

#endif
