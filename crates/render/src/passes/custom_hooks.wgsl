// Default custom hooks: identity. `CustomShader::new(source)` replaces this file's content.
// A custom shader must define these three functions (it may declare helpers too).

// Pass 2, spectral and naive modes: radiance at four wavelengths (`lambda`, nm) of the
// wavelength group `group`, before integration to XYZ. Return the radiance to integrate.
fn custom_spectral(lambda: vec4<f32>, radiance: vec4<f32>, group: u32, ctx: SurfaceContext) -> vec4<f32> {
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
