// Per-wavelength data and Jakob–Hanika upsampling, shared by the shading and custom passes
// (bind group 2). Layouts match src/spectral_data.rs.

// Four node wavelengths. Padding lanes (when N is not a multiple of 4) have zero weights.
struct WavelengthGroup {
    // Node wavelengths in nm.
    lambda: vec4<f32>,
    // The white illuminant's node weights for X, Y, Z (see `white_weights`).
    white_x: vec4<f32>,
    white_y: vec4<f32>,
    white_z: vec4<f32>,
    // Naive box upsampling: 1 in the band (R, G or B) that contains the wavelength, else 0.
    band_r: vec4<f32>,
    band_g: vec4<f32>,
    band_b: vec4<f32>,
    _pad: vec4<f32>,
    // The white's weights split by those bands (see `box_white_weights`).
    band_white_r: mat3x4<f32>,
    band_white_g: mat3x4<f32>,
    band_white_b: mat3x4<f32>,
};

// A light. Its node weights live in `light_weights[light * n_groups + group]`.
struct GpuLight {
    // xyz position (point/spot) or direction the light travels (directional); w = kind
    // (0 directional, 1 point, 2 spot, 3 polygon).
    pos_kind: vec4<f32>,
    // xyz spot direction (unit, away from the light); w = range (0 = infinite).
    dir_range: vec4<f32>,
    // Spot: x = cos(outer cone), y = 1/(cos(inner) - cos(outer)). Directional: z = 1 for a
    // stand-in for diffuse sky light (scene::sky). w unused.
    cone: vec4<f32>,
    // Linear-sRGB emission × intensity, used in rgb mode.
    rgb: vec4<f32>,
    // Spectral modes: XYZ of the light seen by a reflectance of one (Σ of its node weights),
    // for the terms that do not depend on the reflectance (specular). w unused.
    xyz: vec4<f32>,
    // Polygon lights (kind 3, emissive surfaces): vertices in pos_kind.xyz, dir_range.xyz,
    // cone.xyz (cone.w = area) and extra.xyz (a copy of the third for a triangle); extra.w =
    // vertex count.
    extra: vec4<f32>,
};

fn polygon_vertex(li: u32, i: u32) -> vec3<f32> {
    let l = lights[li];
    switch i {
        case 0u: { return l.pos_kind.xyz; }
        case 1u: { return l.dir_range.xyz; }
        case 2u: { return l.cone.xyz; }
        default: { return l.extra.xyz; }
    }
}

fn polygon_count(li: u32) -> u32 {
    return u32(lights[li].extra.w);
}

fn polygon_centroid(li: u32) -> vec3<f32> {
    let n = polygon_count(li);
    var c = vec3<f32>(0.0);
    for (var i = 0u; i < n; i++) {
        c += polygon_vertex(li, i);
    }
    return c / f32(n);
}

// Unit normal of the emitting side (the vertices wind counter-clockwise seen from it).
fn polygon_normal(li: u32) -> vec3<f32> {
    let a = polygon_vertex(li, 0u);
    return normalize(cross(polygon_vertex(li, 1u) - a, polygon_vertex(li, 2u) - a));
}

// Unit direction from `p` towards light `li` (xyz) and the light's distance falloff at `p`
// (w): 1 for a directional light; 1/r² × the glTF range window × the spot cone otherwise.
fn light_incidence(li: u32, p: vec3<f32>) -> vec4<f32> {
    let light = lights[li];
    let kind = u32(light.pos_kind.w);
    if (kind == 0u) {
        return vec4<f32>(-light.pos_kind.xyz, 1.0);
    }
    if (kind == 3u) {
        // A polygon seen from afar: a point at its centroid with intensity L·area·cos (the
        // shading pass integrates polygons exactly; this serves the custom hooks).
        let c = polygon_centroid(li);
        let d = c - p;
        let dist2 = max(dot(d, d), 1e-30);
        let wi = d * inverseSqrt(dist2);
        let cos_l = max(dot(polygon_normal(li), -wi), 0.0);
        return vec4<f32>(wi, light.cone.w * cos_l / dist2);
    }
    let d = light.pos_kind.xyz - p;
    let dist2 = max(dot(d, d), 1e-30);
    let wi = d * inverseSqrt(dist2);
    var atten = 1.0 / dist2;
    let range = light.dir_range.w;
    if (range > 0.0) {
        let r = dist2 / (range * range);
        let w = clamp(1.0 - r * r, 0.0, 1.0);
        atten *= w * w;
    }
    if (kind == 2u) {
        let cd = dot(light.dir_range.xyz, -wi);
        let t = clamp((cd - light.cone.x) * light.cone.y, 0.0, 1.0);
        atten *= t * t;
    }
    return vec4<f32>(wi, atten);
}

@group(2) @binding(0) var<storage, read> wavelengths: array<WavelengthGroup>;
@group(2) @binding(1) var<storage, read> lights: array<GpuLight>;
// Node weights of each light (src/spectral_data.rs, color::quadrature): column c of
// `light_weights[li * n_groups + g]` holds, for the group's four nodes, what the node's
// reflectance is multiplied by to give channel c (X, Y, Z) of the light reflected there, so
// that XYZ = Σ_g ρ_g · light_weights[li * n_groups + g] (a vec4 × mat3x4 product). The
// weights carry the light's spectrum, the observer and the quadrature rule (midpoint or
// prefiltered) together: the shader does not know which rule made them.
@group(2) @binding(2) var<storage, read> light_weights: array<mat3x4<f32>>;
// The coefficient table as one 3D texture: x = i, y = j, z = l·res + k; rgb = (c0, c1, c2).
@group(2) @binding(3) var coeff_table: texture_3d<f32>;
// The table's axes (render::coeff_table::GpuCoeffTable::axes): [0, res) the brightness levels
// (the largest channel at each k), [res, 2·res) the chroma nodes (channel ratio at each i or j),
// then CHROMA_WARP and CHROMA_WARP_SLOPE of color::upsample::table::chroma_weight.
@group(2) @binding(4) var<storage, read> coeff_scale: array<f32>;

// Entries of each axis's interval index (render::coeff_table::AXIS_INDEX; src/layout_tests.rs
// checks it). The indices follow the chroma weight's constants in coeff_scale.
const AXIS_INDEX: u32 = 1024u;

// Largest n with coeff_scale[first + n] <= v, clamped to [0, res - 2], and the interval's two
// nodes (the weights need them: returned rather than loaded again): the interval index
// `index` (at coeff_scale[index]: brightness or chroma, coeff_table::interval_index) gives the
// interval at floor(v · AXIS_INDEX) / AXIS_INDEX, then a step up per node between that and v —
// none or one on spectra's grids, against the six dependent loads of a binary search.
struct Interval {
    n: u32,
    lo: f32,
    hi: f32,
};

fn find_interval(v: f32, first: u32, index: u32, res: u32) -> Interval {
    let vv = select(0.0, min(v, 1.0), v > 0.0);
    var n = u32(coeff_scale[index + min(u32(vv * f32(AXIS_INDEX)), AXIS_INDEX - 1u)]);
    var lo = coeff_scale[first + n];
    var hi = coeff_scale[first + n + 1u];
    while (n < res - 2u && hi <= v) {
        n++;
        lo = hi;
        hi = coeff_scale[first + n + 1u];
    }
    return Interval(n, lo, hi);
}

// σ⁻¹(z) clamped to [1e-6, 1 − 2e-4]: color::upsample::table::z_logit (same constants).
fn z_logit(z_in: f32) -> f32 {
    let z = clamp(z_in, 1e-6, 1.0 - 2e-4);
    return (2.0 * z - 1.0) / (2.0 * sqrt(z * (1.0 - z)));
}

// Brightness weight in σ⁻¹ space for cells below 0.5, linear above, as
// color::upsample::table::z_weight: a weight linear in z bends dark greys between two levels
// (−3.9 % at 0.01); linear in σ⁻¹(z) keeps them exact.
fn z_weight(z: f32, s0: f32, s1: f32) -> f32 {
    let h0 = z_logit(s0);
    let h1 = z_logit(s1);
    var w = 0.0;
    if (h1 > h0 && s1 <= 0.5) {
        w = (z_logit(z) - h0) / (h1 - h0);
    } else if (s1 > s0) {
        w = (z - s0) / (s1 - s0);
    }
    return clamp(w, 0.0, 1.0);
}

// Chroma weight at the channel ratio x in the cell between the chroma nodes r0 and r1, as
// color::upsample::table::chroma_weight: linear in x / (x + A), A = CHROMA_WARP + CHROMA_WARP_SLOPE·other
// (constants at the end of coeff_scale), which follows how the coefficients move next to a
// zero channel (a linear weight missed sRGB (0.92, 0, 0.0073) by ΔE2000 0.5 between two exact nodes).
fn chroma_weight(x: f32, r0: f32, r1: f32, other: f32, res: u32) -> f32 {
    let a = coeff_scale[2u * res] + coeff_scale[2u * res + 1u] * other;
    return clamp((x - r0) * (r1 + a) / ((r1 - r0) * (x + a)), 0.0, 1.0);
}

// Jakob–Hanika coefficients of a reflectance in [0, 1]³: color::upsample::CoeffTable::fetch.
// Light colours come from the negated complement fetch (σ(−x) = 1 − σ(x), colour (1,1,1) − rgb),
// blended in by a smoothstep of the lowest channel over [0.3, 0.5] (table::white_blend, same
// constants): coefficient interpolation next to white is poor, next to black it is smooth.
fn fetch_coeffs(rgb_in: vec3<f32>, res: u32) -> vec3<f32> {
    return fetch_coeffs_two(rgb_in, true, vec3<f32>(0.0), false, res).a;
}

struct CoeffPair {
    a: vec3<f32>,
    b: vec3<f32>,
};

// The smoothstep of the lowest channel over [0.3, 0.5] that blends in the complement's fetch
// (table::white_blend, same constants).
fn white_blend(rgb: vec3<f32>) -> f32 {
    let lo = min(rgb.x, min(rgb.y, rgb.z));
    let u = clamp((lo - 0.3) / (0.5 - 0.3), 0.0, 1.0);
    return u * u * (3.0 - 2.0 * u);
}

// The colour's fetch `d` and its complement's `comp` blended by `alpha` as CoeffTable::fetch.
fn blend_complement(d: vec3<f32>, comp: vec3<f32>, alpha: f32) -> vec3<f32> {
    if (alpha <= 0.0) {
        return d;
    }
    if (alpha >= 1.0) {
        return comp;
    }
    return d + alpha * (comp - d);
}

// `fetch_coeffs` of `a_in` where `use_a` and of `b_in` where `use_b` (zero where not), through
// one call of the fetch in a loop over the none to four that they need (each colour its own
// fetch, its complement's, or both). A CPU driver runs every copy of the fetch's code for every
// pixel, taken or not (a branch, or a loop of no iterations): one copy is the least it can
// cost; a GPU runs the iterations a pixel needs.
fn fetch_coeffs_two(a_in: vec3<f32>, use_a: bool, b_in: vec3<f32>, use_b: bool, res: u32) -> CoeffPair {
    let a = clamp(a_in, vec3<f32>(0.0), vec3<f32>(1.0));
    let b = clamp(b_in, vec3<f32>(0.0), vec3<f32>(1.0));
    let alpha_a = white_blend(a);
    let alpha_b = white_blend(b);
    // Jobs 0 and 1: a's own fetch and its complement's; 2 and 3: b's. Each colour needs the
    // jobs [first, end) of its pair.
    let first_a = select(0u, 1u, alpha_a >= 1.0);
    let end_a = select(first_a, select(1u, 2u, alpha_a > 0.0), use_a);
    let first_b = select(0u, 1u, alpha_b >= 1.0);
    let end_b = select(first_b, select(1u, 2u, alpha_b > 0.0), use_b);
    let n_a = end_a - first_a;
    let n = n_a + end_b - first_b;
    var d_a = vec3<f32>(0.0);
    var comp_a = vec3<f32>(0.0);
    var d_b = vec3<f32>(0.0);
    var comp_b = vec3<f32>(0.0);
    for (var k = 0u; k < n; k++) {
        let job = select(2u + first_b + (k - n_a), first_a + k, k < n_a);
        let colour = select(a, b, job >= 2u);
        let complement = (job & 1u) == 1u;
        let c = fetch_coeffs_direct(select(colour, vec3<f32>(1.0) - colour, complement), res);
        d_a = select(d_a, c, job == 0u);
        comp_a = select(comp_a, -c, job == 1u);
        d_b = select(d_b, c, job == 2u);
        comp_b = select(comp_b, -c, job == 3u);
    }
    return CoeffPair(blend_complement(d_a, comp_a, alpha_a), blend_complement(d_b, comp_b, alpha_b));
}

// rgb2spec's fetch of a colour in [0, 1]³ (table::CoeffTable::fetch_direct): manual trilinear
// interpolation with textureLoad (exact in f32; rgba32float is not filterable everywhere),
// brightness weight in σ⁻¹ space (z_weight).
fn fetch_coeffs_direct(rgb: vec3<f32>, res: u32) -> vec3<f32> {
    var l = 0u;
    if (rgb.y >= rgb[l]) { l = 1u; }
    if (rgb.z >= rgb[l]) { l = 2u; }
    let z = rgb[l];
    // Black: any (x, y) on the z = 0 slice gives the same spectrum; use the corner.
    // Channel ratios (divided as on the CPU), located on the table's chroma nodes.
    let x = select(0.0, rgb[(l + 1u) % 3u] / z, z > 0.0);
    let y = select(0.0, rgb[(l + 2u) % 3u] / z, z > 0.0);
    let z_index = 2u * res + 2u;
    let chroma_index = z_index + AXIS_INDEX;
    let xi = find_interval(x, res, chroma_index, res);
    let yi = find_interval(y, res, chroma_index, res);
    let zi = find_interval(z, 0u, z_index, res);
    let x1 = chroma_weight(x, xi.lo, xi.hi, y, res);
    let y1 = chroma_weight(y, yi.lo, yi.hi, x, res);
    let z1 = z_weight(z, zi.lo, zi.hi);
    let base = vec3<i32>(i32(xi.n), i32(yi.n), i32(l * res + zi.n));
    let c000 = textureLoad(coeff_table, base, 0).xyz;
    let c100 = textureLoad(coeff_table, base + vec3<i32>(1, 0, 0), 0).xyz;
    let c010 = textureLoad(coeff_table, base + vec3<i32>(0, 1, 0), 0).xyz;
    let c110 = textureLoad(coeff_table, base + vec3<i32>(1, 1, 0), 0).xyz;
    let c001 = textureLoad(coeff_table, base + vec3<i32>(0, 0, 1), 0).xyz;
    let c101 = textureLoad(coeff_table, base + vec3<i32>(1, 0, 1), 0).xyz;
    let c011 = textureLoad(coeff_table, base + vec3<i32>(0, 1, 1), 0).xyz;
    let c111 = textureLoad(coeff_table, base + vec3<i32>(1, 1, 1), 0).xyz;
    let c00 = mix(c000, c100, x1);
    let c10 = mix(c010, c110, x1);
    let c01 = mix(c001, c101, x1);
    let c11 = mix(c011, c111, x1);
    return mix(mix(c00, c10, y1), mix(c01, c11, y1), z1);
}

// s(x) = ½ + x / (2·√(1 + x²)) at four wavelengths: 2 fma for the polynomial, then
// fma + inverseSqrt + mul + fma. x is clamped so that x² stays finite.
fn sigmoid4(c: vec3<f32>, lambda: vec4<f32>) -> vec4<f32> {
    let x = clamp(fma(fma(vec4<f32>(c.x), lambda, vec4<f32>(c.y)), lambda, vec4<f32>(c.z)),
                  vec4<f32>(-1e18), vec4<f32>(1e18));
    return fma(0.5 * x, inverseSqrt(fma(x, x, vec4<f32>(1.0))), vec4<f32>(0.5));
}

// Naive box upsampling: each wavelength takes the value of the band it falls in.
fn box4(rgb: vec3<f32>, g: u32) -> vec4<f32> {
    let w = wavelengths[g];
    return fma(vec4<f32>(rgb.r), w.band_r, fma(vec4<f32>(rgb.g), w.band_g, rgb.b * w.band_b));
}

// The weights of light `li` for group `g` (see `light_weights`).
fn light_w(li: u32, g: u32, n_groups: u32) -> mat3x4<f32> {
    return light_weights[li * n_groups + g];
}

// The white illuminant's node weights for group `g`: emission uses the "illuminant"
// upsampling ρ(λ)·W(λ), so an emissive surface is its node reflectance times these.
fn white_weights(g: u32) -> mat3x4<f32> {
    let w = wavelengths[g];
    return mat3x4<f32>(w.white_x, w.white_y, w.white_z);
}

// The white's node weights with a box spectrum (one value per naive band, e.g. a per-channel
// transmittance) folded in: Σ_b box[b]·(weights of W·1_b). A smooth node spectrum times these
// integrates the product exactly where `box4` at the nodes would smear each band's step over
// the nodes around it (at N = 8 they are 44 nm apart).
fn box_white_weights(box: vec3<f32>, g: u32) -> mat3x4<f32> {
    let w = wavelengths[g];
    return w.band_white_r * box.r + w.band_white_g * box.g + w.band_white_b * box.b;
}

// Node radiance in weighted form: `m[c]` holds channel c's weighted node values, so a
// wavelength-dependent factor f (transmittance, scattering) multiplies each column.
fn s3_scale(m: mat3x4<f32>, f: vec4<f32>) -> mat3x4<f32> {
    return mat3x4<f32>(m[0] * f, m[1] * f, m[2] * f);
}

// XYZ of weighted node radiance: the sum of each column's lanes.
fn s3_xyz(m: mat3x4<f32>) -> vec3<f32> {
    return vec4<f32>(1.0) * m;
}
