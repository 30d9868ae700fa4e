// Linear blend skinning (hairtool.character.skinning's kernel on the GPU): a vertex moved by the
// weighted sum of its four joints' skin matrices (posed world matrix times inverse bind). The
// matrices come in a float texture, one row per joint of the skin, texel c holding column c,
// so a skin has as many joints as a texture has rows.

uniform sampler2D u_joints;

in vec3 in_position;   // at bind time, in the mesh node's space
in ivec4 in_joints;    // rows of u_joints
in vec4 in_weights;    // summing to 1

mat4 joint_matrix(int j) {
    return mat4(
        texelFetch(u_joints, ivec2(0, j), 0),
        texelFetch(u_joints, ivec2(1, j), 0),
        texelFetch(u_joints, ivec2(2, j), 0),
        texelFetch(u_joints, ivec2(3, j), 0)
    );
}

mat4 skin_matrix() {
    return in_weights.x * joint_matrix(in_joints.x) + in_weights.y * joint_matrix(in_joints.y)
         + in_weights.z * joint_matrix(in_joints.z) + in_weights.w * joint_matrix(in_joints.w);
}
