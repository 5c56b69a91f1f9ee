// The see-through meshes' back faces (passes/back_faces.rs): where a view ray refracted into a
// closed volume leaves it. Prepended: wgsl/common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

struct BackOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) world: vec3<f32>,
};

@vertex
fn vs_back(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> BackOut {
    return BackOut(frame.view_proj * vec4<f32>(position, 1.0), normal, position);
}

// xyz: the outward unit normal (the mesh's vertex normal: a normal map describes the side one
// sees); w: the face's linear depth (`linear_depth` in passes/transmission.wgsl).
@fragment
fn fs_back(in: BackOut) -> @location(0) vec4<f32> {
    let c = frame.view_proj * vec4<f32>(in.world, 1.0);
    let depth = select(c.w, 1.0 - c.z, (frame.flags & FLAG_ORTHO) != 0u);
    return vec4<f32>(normalize(in.normal), depth);
}
