// Default custom hooks: identity. A custom shader defines any of these functions (it
// may declare helpers too); the renderer adds this file's definition of each one it leaves out
// (`CustomShader::assembled`).

// Pass 2, every mode, once per pixel before any other pass-2 hook (on a surface `ctx.normal`
// is set): per-pixel work that does not depend on wavelength, kept in private variables for the
// hooks called per group and light. Preparing here rather than behind a "done yet" flag in each
// hook keeps one copy of that work in the shader: a CPU driver runs a skipped branch's code all
// the same, so a flagged copy in a per-group hook cost it the whole preparation again per group.
fn custom_prepare(ctx: SurfaceContext) {
}

// Pass 2, spectral and naive modes, once per group of four node wavelengths (`lambda`, nm),
// before integration. `radiance[c]` is the light leaving the surface towards the camera at
// the four nodes (on a background pixel the environment's, as `custom_rgb` receives it; at a
// see-through surface its own reflection: the light through it, which has had the hook along
// its own view ray, is added after), in weighted form for channel c (X, Y, Z): XYZ = Σ over groups and lanes of
// `radiance[c]`. A factor that depends on wavelength (a transmittance, say) multiplies every
// column (`s3_scale`); light added along the ray is a light's node weights (`light_w`) or the
// white's (`white_weights`) times its factor. Return the radiance to integrate. Defining this
// hook makes the shading loop carry the specular term through the nodes (a few fma per light).
fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    return radiance;
}

// Pass 2, rgb mode: linear-sRGB radiance of the pixel.
fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> {
    return radiance;
}

// Pass 3, every mode: the HDR linear-sRGB colour after shading. Return the new colour.
fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32> {
    return hdr;
}

// Pass 2, every mode, once per light and pixel on a lit surface: a factor on light `li`'s
// direct light at the surface (before `custom_spectral`/`custom_rgb`) — 0 for a light whose
// effect the hooks account for themselves.
fn custom_light_surface(li: u32, ctx: SurfaceContext) -> f32 {
    return 1.0;
}

// Pass 2, spectral and naive modes, once per group on a lit surface: irradiance the medium
// brings to the surface, in weighted form (like a light's `light_w` times its irradiance),
// as it reaches the camera (the hook applies the medium's attenuation along the view). The
// renderer reflects it with the surface's diffuse lobe and adds it after `custom_spectral`.
fn custom_irradiance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    return mat3x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
}

// Pass 2, rgb mode: the same as linear-sRGB irradiance.
fn custom_irradiance_rgb(ctx: SurfaceContext) -> vec3<f32> {
    return vec3<f32>(0.0);
}

// Pass 2, spectral and naive modes, per light and group on a lit surface: a factor per node
// wavelength on light `li`'s direct light at the surface (a medium's transmittance between
// the light and the surface), applied to its diffuse and specular terms.
fn custom_light_transmittance(li: u32, lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
    return vec4<f32>(1.0);
}

// Pass 2, rgb mode: the same per linear-sRGB channel.
fn custom_light_transmittance_rgb(li: u32, ctx: SurfaceContext) -> vec3<f32> {
    return vec3<f32>(1.0);
}

// Pass 2, spectral and naive modes, per group on a lit surface: a factor per node wavelength on
// the environment's light at the surface (a medium's transmittance between the environment and
// the surface), applied to its diffuse and specular terms.
fn custom_env_transmittance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
    return vec4<f32>(1.0);
}

// Pass 2, rgb mode: the same per linear-sRGB channel.
fn custom_env_transmittance_rgb(ctx: SurfaceContext) -> vec3<f32> {
    return vec3<f32>(1.0);
}
