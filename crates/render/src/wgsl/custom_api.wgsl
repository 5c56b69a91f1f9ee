// The contract between the renderer and a custom shader (bind group 3, and the context
// structs passed to the hooks). See src/passes/custom.rs for the documentation.

struct CustomUniforms {
    // Sixteen free parameters, set with `CustomShader::params`.
    params: array<vec4<f32>, 4>,
    // Number of spectra in `custom_spectra` per wavelength group.
    n_spectra: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(3) @binding(0) var<uniform> custom: CustomUniforms;
// `CustomShader::spectra` resampled at the current wavelengths:
// custom_spectra[group * 4 + s] holds spectrum s < 4 at the group's four wavelengths, and
// custom_spectra[s * n_groups + group] spectrum s ≥ 4 (tables).
@group(3) @binding(1) var<storage, read> custom_spectra: array<vec4<f32>>;

// What the hooks know about the point being shaded.
struct SurfaceContext {
    // World position of the visible surface (on the far plane for background pixels).
    world_pos: vec3<f32>,
    // Unit world normal (zero for background).
    normal: vec3<f32>,
    // Unit direction from the camera through the pixel (the camera's forward axis everywhere
    // for an orthographic camera).
    view_dir: vec3<f32>,
    // Distance from `origin` to `world_pos` in scene units (0 for background).
    distance: f32,
    // Where the view ray starts: the camera position, or for an orthographic camera the point
    // of the camera's plane on this pixel's ray.
    origin: vec3<f32>,
    // True where no geometry was drawn.
    background: bool,
    // Pixel coordinates.
    pixel: vec2<u32>,
};

// The context of the pixel at fragment position `pos` whose G-buffer depth is `depth`, as the
// shading and custom passes both build it. The normal is left zero for the caller to fill.
fn surface_context(pos: vec2<f32>, depth: f32, f: FrameUniforms) -> SurfaceContext {
    let background = is_far_depth(depth);
    let p = world_from_depth(pos, depth, f);
    let origin = view_origin(pos, p, f);
    let to_p = p - origin;
    var ctx: SurfaceContext;
    ctx.origin = origin;
    ctx.world_pos = p;
    ctx.view_dir = normalize(to_p);
    ctx.distance = select(length(to_p), 0.0, background);
    ctx.background = background;
    ctx.pixel = vec2<u32>(pos);
    ctx.normal = vec3<f32>(0.0);
    return ctx;
}
