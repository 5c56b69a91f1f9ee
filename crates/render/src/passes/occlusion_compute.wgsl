// The occlusion pass's compute stage (passes::shading::ShadingStage::Compute): one invocation per
// pixel into the occlusion target. Appended to occlusion_pass.wgsl only in that stage, whose
// layout binds the output.

@group(1) @binding(4) var occlusion_out: texture_storage_2d<r32float, write>;

@compute @workgroup_size(SCREEN_GROUP, SCREEN_GROUP)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (all(id.xy < textureDimensions(occlusion_out))) {
        textureStore(occlusion_out, id.xy, occlusion_at(fullscreen_at(id.xy)));
    }
}
