// Shadow pass: depth only, rendered from the shadow-casting light. Prepended: wgsl/common.wgsl.

@group(0) @binding(0) var<uniform> frame: FrameUniforms;

@vertex
fn vs_shadow(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return frame.shadow_view_proj * vec4<f32>(position, 1.0);
}
