// What the composite textures share (compose.rs). A composite calls its
// children's type functions directly (not `texture_eval`, which would make
// the call graph recursive); a child that varies is an entry of the
// scene's texture table, whose parameters it finds through the texture
// directory (at header word H_TEXTURES: per texture its type, parameter
// offset, 0, 0).

fn texture_child_params(id: u32) -> u32 {
    return param_u32(param_u32(H_TEXTURES) + 4u * id + 1u);
}
