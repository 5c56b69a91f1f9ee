// Default custom hooks: identity. A custom shader defines any of these three functions (it
// may declare helpers too); the renderer adds this file's definition of each one it leaves out
// (`CustomShader::assembled`).

// Pass 2, spectral and naive modes, once per group of four node wavelengths (`lambda`, nm),
// before integration. `radiance[c]` is the light leaving the surface towards the camera at
// the four nodes, in weighted form for channel c (X, Y, Z): XYZ = Σ over groups and lanes of
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
