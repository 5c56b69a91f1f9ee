// Integer hashes: the same bits on every driver. The `fract(sin(x) · 43758.5453)` hash that the
// occlusion and soft shadows used before is not: far from zero its value is the driver's `sin`
// precision, and an NVIDIA GPU drew a different occlusion pattern from lavapipe's (one
// silhouette pixel of the white furnace 1.1 % dark, docs/benchmark.md "H200").

// PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering").
fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Two independent uniform numbers in [0, 1) from two words (a pixel, a texel's bits) and a salt.
fn hash2_unit(p: vec2<u32>, salt: u32) -> vec2<f32> {
    let a = pcg_hash(p.x ^ pcg_hash(p.y ^ pcg_hash(salt)));
    let b = pcg_hash(a ^ salt);
    return vec2<f32>(f32(a >> 8u), f32(b >> 8u)) * (1.0 / 16777216.0);
}
