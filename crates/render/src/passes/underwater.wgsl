// Underwater hooks (Monzón et al. 2024, plus ray-marched single scattering), installed by
// `underwater::shader`. See src/passes/underwater.rs for the model, the parameter layout and the
// assumptions; the CPU reference of every formula is `scene::water` (`single` for the march).
//
// custom.params = `UwParams` below (`underwater::WaterParams`)
// custom_spectra[g * 4 + 0..3] = b, c, Kd at the group's wavelengths
//
// Water coefficients are vec4: four node wavelengths in spectral/naive modes, (R, G, B, unused)
// in rgb mode, so both modes run the same code. Light is in weighted form (mat3x4, see
// custom_hooks.wgsl): in spectral/naive modes column c holds channel c's node weights, so the
// light's lines are integrated by the renderer's quadrature and the water's smooth factors
// multiply node by node; in rgb mode column 0 holds (R, G, B, 0) and the others are zero.

// The phase function, the path integral and the equiangular steps: medium_common.wgsl.
const UW_INV_4PI: f32 = MEDIUM_INV_4PI;
// MAX_LIGHTS in src/scene_gpu.rs (src/layout_tests.rs checks it).
const UW_MAX_LIGHTS: u32 = 32u;
// Pipeline-overridable constants, set by `underwater::shader_with` (`CustomShader::constants`).
// Whether the shader marches at all: `false` when the steps are 0, so that the paper's model
// runs without the march (its code and private arrays cost about 2× the hook on a CPU driver
// even when skipped at run time; the override is a constant by the time the driver compiles).
override UW_MARCH: bool = true;
// Whether upward rays that reach the surface see it (Snell's window, Fresnel reflection, total
// internal reflection); `false` for the paper's model. The refractive index and the sky's
// normalisation 1/(π·T̄) come from scene::water (WATER_IOR, fresnel).
override UW_SURFACE: bool = true;
override UW_N: f32;
override UW_SKY_NORM: f32;
// The light-field model (`underwater::Options::light_field`, scene::water::light_field): the
// in-scattering source J(z, view, λ) of the water's own diffuse light field replaces the
// paper's isotropic term, and surfaces are attenuated by the field's downwelling irradiance
// E_d(z) (UW_TABLE_KD) instead of the tabulated Kd. `underwater::shader_with` sets these and
// the table's depth range; the table's layout is scene::water::light_field's.
override UW_TABLE: bool = true;
override UW_TABLE_KD: bool = true;
// Surfaces lit by the sun's unscattered beam (e^{−c·z/μ}, shadowed) plus the column's diffuse
// irradiance for their normal (light_field::LightFieldTable::irradiance), the sky stand-ins
// left out (their light is in the table): `Options::irradiance`.
override UW_IRRADIANCE: bool = true;
// Fraction f of the scattering within the light-field model's forward cone
// (light_field::LightFieldKey::forward_cone; 0 for the other models): view rays are attenuated
// by c − f·b, and the table's J leaves that scattering out.
override UW_FWD: f32 = 0.0;
override UW_ZMAX: f32 = 40.0;
// The table's layout, set by `underwater::shader_with` from scene::water::light_field
// (N_DEPTH, N_ELEV, N_AZ, 1/ELEV_WARP, N_NORMAL_ELEV, N_NORMAL_AZ): one home for the numbers.
override UW_ND: u32;
override UW_NE: u32;
override UW_NA: u32;
override UW_ELEV_INV_WARP: f32;
override UW_NNE: u32;
override UW_NNA: u32;
override UW_NC: u32 = UW_ND * UW_NE * UW_NA;
// Spectrum indices (custom_spectra[s * n_groups + group]): two tables of one block each — 0
// the column closed by the sea floor, 1 the bottomless column (the same table twice when the
// scene has no floor) — each J per cell, E_d per depth node, the surface's reflection of the
// water and of the floor per view node, the irradiance per depth and normal node; then the RGB
// mode's copies, three constants each.
override UW_NV: u32 = UW_NE * UW_NA;
override UW_L_J: u32 = 0u;
override UW_L_ED: u32 = UW_NC;
override UW_L_SURF: u32 = UW_NC + UW_ND;
override UW_L_SURF_FLOOR: u32 = UW_NC + UW_ND + UW_NV;
override UW_L_IRR: u32 = UW_NC + UW_ND + 2u * UW_NV;
override UW_BLOCK: u32 = UW_L_IRR + UW_ND * UW_NNE * UW_NNA;
override UW_T_RGB: u32 = 4u + 2u * UW_BLOCK;
// The sea floor's horizontal extent (scene units: min x, min z, max x, max z; set by
// `underwater::shader_with`); the surface mirrors the floor only where the mirrored view lands
// inside it.
override UW_FLOOR_MIN_X: f32 = -1e30;
override UW_FLOOR_MIN_Z: f32 = -1e30;
override UW_FLOOR_MAX_X: f32 = 1e30;
override UW_FLOOR_MAX_Z: f32 = 1e30;
fn uw_floor_box() -> vec4<f32> {
    return vec4<f32>(UW_FLOOR_MIN_X, UW_FLOOR_MIN_Z, UW_FLOOR_MAX_X, UW_FLOOR_MAX_Z);
}
// Lights with single scattering, and march steps: SS_LIGHTS and MAX_STEPS in underwater.rs
// (src/layout_tests.rs checks them; they size private arrays, so they cannot be overrides).
const UW_SS_LIGHTS: u32 = 4u;
const UW_MAX_STEPS: u32 = 32u;
// The hooks' parameters: byte for byte `underwater::WaterParams` (src/layout_tests.rs checks the
// layout), read from the custom shader's sixteen floats in field order.
struct UwParams {
    // Camera depth z0 (m), metres per scene unit, march steps M (0 = the paper's model alone),
    // Henyey–Greenstein g.
    depth: f32,
    scale: f32,
    steps: f32,
    g: f32,
    // c at the RGB mode's three wavelengths, smallest c over the range.
    c_rgb: vec3<f32>,
    c_min: f32,
    // Kd at the RGB mode's three wavelengths, 1 = scalar irradiance by Gershun's law.
    kd_rgb: vec3<f32>,
    gershun: f32,
    // b at the RGB mode's three wavelengths, 1 = take the beams out of L_ms.
    b_rgb: vec3<f32>,
    split_beams: f32,
}

fn uw_params() -> UwParams {
    let p = custom.params;
    return UwParams(p[0].x, p[0].y, p[0].z, p[0].w, p[1].xyz, p[1].w, p[2].xyz, p[2].w, p[3].xyz, p[3].w);
}

// A downward or level ray has no end: directional lights are marched (for shadows) over the
// first UW_CAP optical depths of the clearest wavelength, the rest is integrated unshadowed;
// point and spot lights are marched over at most that length.
const UW_CAP: f32 = 6.0;

// Per-pixel, wavelength-independent march, filled once by `uw_prepare` (from `custom_prepare`,
// before the hooks that read it) and reused by every wavelength group: for light slot j and step k, weight W = phase × visibility × geometry and
// optical path s (metres) so that the light's single scattering is b·E·Σ_k W·e^{−c·s}. For a
// directional slot only s at the first step is stored: the later ones follow from q and the
// segment length in `uw_dir` (see `uw_single_scatter`).
var<private> uw_n: u32 = 0u;
var<private> uw_steps: u32 = 0u;
var<private> uw_light: array<u32, UW_SS_LIGHTS>;
// Directional slots: x = q (the beam's optical path grows by c·q per metre along the ray),
// y = segment length (m), z = tail weight, w = tail path (m). Point/spot slots: all zero.
var<private> uw_dir: array<vec4<f32>, UW_SS_LIGHTS>;
var<private> uw_w: array<f32, 128>;
// Directional slots whose every march sample is lit: their sum has a closed form.
var<private> uw_lit: array<bool, UW_SS_LIGHTS>;
var<private> uw_s: array<f32, 128>;
// Point/spot slots: the view part of `uw_s` (metres from the camera), attenuated by c − f·b
// instead of c.
var<private> uw_tv: array<f32, 128>;
// Path length (m) to the hit or the surface, and whether the ray runs forever.
var<private> uw_d: f32 = 0.0;
var<private> uw_infinite: bool = false;

// The same over the whole view ray: to the hit or surface, or to infinity (k > 0 there).
fn uw_ray_integral(k: vec4<f32>) -> vec4<f32> {
    return uw_integral_to(k, uw_d, uw_infinite);
}

fn uw_integral_to(k: vec4<f32>, d: f32, infinite: bool) -> vec4<f32> {
    if (infinite) {
        return 1.0 / k;
    }
    return medium_path_integral(k, d);
}

// Light `li` in weighted form: its node weights for the group, or in rgb mode its linear-sRGB
// colour in column 0.
fn uw_emission(li: u32, group: u32, rgb: bool) -> mat3x4<f32> {
    if (rgb) {
        return mat3x4<f32>(vec4<f32>(lights[li].rgb.rgb, 0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return light_w(li, group, frame.n_groups);
}

const UW_ZERO: mat3x4<f32> = mat3x4<f32>(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));

// The suns' light summed (directional lights that are not sky stand-ins, shining down), in
// weighted form: the light-field table's terms are per unit sun irradiance, so every sun
// multiplies the same factor. Summed once per group and pixel (`uw_sun_group` says which
// group `uw_sun_w` holds) and shared by the in-scattering, the surface's reflection and the
// column's irradiance, instead of a loop over the lights in each.
var<private> uw_sun_group: u32 = 0xffffffffu;
var<private> uw_sun_w: mat3x4<f32>;

fn uw_suns(group: u32, rgb: bool) -> mat3x4<f32> {
    if (uw_sun_group != group) {
        uw_sun_group = group;
        var total = UW_ZERO;
        for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
            let l = lights[li].pos_kind;
            if (u32(l.w) != 0u || l.y >= 0.0 || lights[li].cone.z > 0.5) { continue; }
            total += uw_emission(li, group, rgb);
        }
        uw_sun_w = total;
    }
    return uw_sun_w;
}

// Per-pixel part of the light-field integral, filled by `uw_prepare_table`: the four table
// directions around the view (cell offsets within one depth slice) and their bilinear
// weights; the ray cut at the depth nodes it crosses into pieces, each with its segment i,
// start t0 (m), length (m, < 0 for a piece that runs forever) and depth offset z(t0) − z_i.
var<private> uw_cell: array<u32, 4>;
// At most one piece per depth node the ray crosses, one where it leaves the floored column and
// the last one: N_DEPTH + 2 (a constant, as private arrays need one; layout_tests checks it).
const UW_MAX_PIECES: u32 = 18u;
var<private> uw_cw: vec4<f32>;
var<private> uw_np: u32 = 0u;
var<private> uw_pn: array<u32, UW_MAX_PIECES>;
var<private> uw_pt: array<f32, UW_MAX_PIECES>;
var<private> uw_pl: array<f32, UW_MAX_PIECES>;
var<private> uw_pz: array<f32, UW_MAX_PIECES>;
// Which table each piece reads: 1 (bottomless) where its midpoint lies beyond the floor.
var<private> uw_pd: array<u32, UW_MAX_PIECES>;
// Bit p set: piece p lies below the table's last node (extrapolated; light_field::ray_integral_by).
var<private> uw_beyond: u32 = 0u;
var<private> uw_org: vec3<f32>;
var<private> uw_view: vec3<f32>;
// The first sun's horizontal direction (towards it; zero for a zenith sun or none) and the
// cosine of its beam to the downward vertical (1 without a sun).
var<private> uw_sun_h: vec3<f32>;
var<private> uw_sun_mu: f32 = 1.0;

// Distance (m) along the view from the camera at which it leaves the floor's extent or reaches
// the table's deepest node (the floor), 0 if the camera is not over the floor, ≥ 1e30 if never.
fn uw_floor_exit(w: vec3<f32>, z0: f32) -> f32 {
    let scale = uw_params().scale;
    if (!uw_over_floor(uw_org)) { return 0.0; }
    var te = 1e30;
    if (w.y < -1e-6) { te = (UW_ZMAX - z0) / (-w.y); }
    let o = uw_org.xz;
    let d = w.xz;
    for (var a = 0u; a < 2u; a++) {
        if (d[a] > 1e-9) { te = min(te, (uw_floor_box()[a + 2u] - o[a]) / d[a] * scale); }
        if (d[a] < -1e-9) { te = min(te, (uw_floor_box()[a] - o[a]) / d[a] * scale); }
    }
    return max(te, 0.0);
}

// Whether a scene point (scene units) lies over the sea floor's extent.
fn uw_over_floor(p: vec3<f32>) -> bool {
    return all(p.xz >= uw_floor_box().xy) && all(p.xz <= uw_floor_box().zw);
}

// Table `table`'s entry `local` at the group's wavelengths (rgb: at the RGB wavelengths).
fn uw_tab(table: u32, local: u32, group: u32, rgb: bool) -> vec4<f32> {
    let ng = frame.n_groups;
    if (rgb) {
        let s = UW_T_RGB + 3u * (table * UW_BLOCK + local);
        return vec4<f32>(custom_spectra[s * ng].x, custom_spectra[(s + 1u) * ng].x, custom_spectra[(s + 2u) * ng].x, 0.0);
    }
    return custom_spectra[(4u + table * UW_BLOCK + local) * ng + group];
}

fn uw_depth_node(i: u32) -> f32 {
    let f = f32(i) / f32(UW_ND - 1u);
    return UW_ZMAX * f * sqrt(f);
}

// atan(t) for t in [0, 1] to ~1e-8: one reduction by π/6, then the series to t¹¹. WGSL's
// acos/atan2 may be off by 4096 ulp (Vulkan's precision rules), which moves the table's
// direction interpolation by ~1e-3 of J.
fn uw_atan01(t: f32) -> f32 {
    var a = t;
    var off = 0.0;
    if (t > 0.26794919) {
        a = (t * 1.7320508 - 1.0) / (t + 1.7320508);
        off = 0.52359878;
    }
    let a2 = a * a;
    return off + a * (1.0 - a2 * (1.0 / 3.0 - a2 * (0.2 - a2 * (1.0 / 7.0 - a2 * (1.0 / 9.0 - a2 / 11.0)))));
}

// The angle in [0, π] whose sine is s ≥ 0 and cosine c (any common scale).
fn uw_angle(s: f32, c: f32) -> f32 {
    let ac = abs(c);
    var th = 0.0;
    if (s <= ac) {
        th = uw_atan01(s / max(ac, 1e-30));
    } else {
        th = 1.5707963 - uw_atan01(ac / s);
    }
    return select(th, 3.14159265358979 - th, c < 0.0);
}

// The four cells of a direction table (ne elevations × na azimuths, elevation-major) around the
// fractional node (fe, fk), and their bilinear weights.
struct UwCells {
    index: vec4<u32>,
    w: vec4<f32>,
};

fn uw_cells(fe: f32, fk: f32, ne: u32, na: u32) -> UwCells {
    let e0 = min(u32(floor(fe)), ne - 2u);
    let k0 = min(u32(floor(fk)), na - 2u);
    let te = fe - f32(e0);
    let tk = fk - f32(k0);
    let index = vec4<u32>(e0 * na + k0, e0 * na + k0 + 1u, (e0 + 1u) * na + k0, (e0 + 1u) * na + k0 + 1u);
    return UwCells(index, vec4<f32>((1.0 - te) * (1.0 - tk), (1.0 - te) * tk, te * (1.0 - tk), te * tk));
}

// The angle in [0, π] between a horizontal direction h and the first sun's (`uw_sun_h`); 0 for
// a vertical direction or without a sun.
fn uw_sun_azimuth(h: vec3<f32>) -> f32 {
    if (length(h) > 1e-6 && dot(uw_sun_h, uw_sun_h) > 0.5) {
        return uw_angle(abs(cross(uw_sun_h, h).y), dot(uw_sun_h, h));
    }
    return 0.0;
}

// Fractional elevation node of the polar angle th (light_field::elevation_coord): nodes are
// denser near the horizon.
fn uw_elev_coord(th: f32) -> f32 {
    let u = clamp(th / 1.5707963 - 1.0, -1.0, 1.0);
    let t = select(sign(u) * pow(abs(u), UW_ELEV_INV_WARP), 0.0, abs(u) < 1e-20);
    return 0.5 * (t + 1.0) * f32(UW_NE - 1u);
}

// The segment [z_i, z_{i+1}] that holds depth z (the last one beyond the last node): the
// largest i ≤ UW_ND − 2 whose nodes 1 … i all lie above z. In closed form, as the nodes are
// UW_ZMAX·(i/(UW_ND − 1))^1.5: i ≈ (UW_ND − 1)·(z/UW_ZMAX)^(2/3), then one comparison on each
// side with the nodes themselves corrects the guess's rounding, so the answer is the node-by-node
// search's exactly (that search ran up to UW_ND − 2 steps, several times per pixel and group).
fn uw_segment(z: f32) -> u32 {
    let last = UW_ND - 2u;
    // Beyond the table, and NaN, as the search: the last segment.
    if (!(z < UW_ZMAX)) { return last; }
    let g = f32(UW_ND - 1u) * pow(max(z, 0.0) / UW_ZMAX, 2.0 / 3.0);
    var i = min(u32(max(ceil(g) - 1.0, 0.0)), last);
    if (i < last && uw_depth_node(i + 1u) < z) { i++; }
    if (i > 0u && uw_depth_node(i) >= z) { i--; }
    return i;
}

fn uw_add_piece(t0: f32, t1: f32, infinite: bool, z0: f32, wy: f32) {
    if (uw_np >= UW_MAX_PIECES) { return; }
    let tm = select(0.5 * (t0 + t1), t0 + 1.0, infinite);
    let zm = max(z0 - tm * wy, 0.0);
    let i = uw_segment(zm);
    if (zm > UW_ZMAX) { uw_beyond |= 1u << uw_np; }
    uw_pn[uw_np] = i;
    uw_pt[uw_np] = t0;
    uw_pl[uw_np] = select(t1 - t0, -1.0, infinite);
    uw_pz[uw_np] = max(z0 - t0 * wy, 0.0) - uw_depth_node(i);
    // An endless piece runs below the floor's depth, where only the bottomless column makes
    // sense (a view that misses the floor's mesh inside its extent).
    uw_pd[uw_np] = select(1u, 0u, !infinite && uw_over_floor(uw_org + uw_view * (tm / uw_params().scale)));
    uw_np++;
}

fn uw_prepare_table(w: vec3<f32>, z0: f32) {
    // The view relative to the first sun (scene::water::light_field::view_coords).
    var sun_h = vec3<f32>(0.0);
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        if (u32(l.w) == 0u && lights[li].cone.z < 0.5 && l.y < 0.0) {
            let h = vec2<f32>(-l.x, -l.z);
            if (dot(h, h) > 1e-12) { sun_h = vec3<f32>(normalize(h).x, 0.0, normalize(h).y); }
            uw_sun_mu = -l.y;
            break;
        }
    }
    uw_sun_h = sun_h;
    let hw = vec3<f32>(w.x, 0.0, w.z);
    let fe = uw_elev_coord(uw_angle(length(hw), w.y));
    let cell = uw_cells(fe, uw_sun_azimuth(hw) / 3.14159265358979 * f32(UW_NA - 1u), UW_NE, UW_NA);
    uw_cell = array<u32, 4>(cell.index.x, cell.index.y, cell.index.z, cell.index.w);
    uw_cw = cell.w;
    // Pieces between the node depths the ray crosses, in order along the ray, also cut where
    // the ray leaves the floored column (the floor's extent, or its depth): each piece reads
    // one table, chosen at its midpoint.
    uw_np = 0u;
    uw_beyond = 0u;
    var t = 0.0;
    let wy = w.y;
    let t_exit = uw_floor_exit(w, z0);
    if (abs(wy) > 1e-6) {
        for (var n = 1u; n < UW_ND; n++) {
            // Going down the nodes come in increasing depth, going up in decreasing depth; the
            // last node too (below it the column is extrapolated), never the surface.
            let i = select(UW_ND - 1u - n, n, wy < 0.0);
            if (i == 0u) { continue; }
            let tc = (z0 - uw_depth_node(i)) / wy;
            if (tc > t && (uw_infinite || tc < uw_d)) {
                if (t_exit > t && t_exit < tc) {
                    uw_add_piece(t, t_exit, false, z0, wy);
                    t = t_exit;
                }
                uw_add_piece(t, tc, false, z0, wy);
                t = tc;
            }
        }
    }
    if (uw_infinite) {
        if (t_exit > t && t_exit < 1e30) {
            uw_add_piece(t, t_exit, false, z0, wy);
            t = t_exit;
        }
        uw_add_piece(t, t, true, z0, wy);
    } else if (uw_d > t) {
        if (t_exit > t && t_exit < uw_d) {
            uw_add_piece(t, t_exit, false, z0, wy);
            t = t_exit;
        }
        uw_add_piece(t, uw_d, false, z0, wy);
    }
}

// J at depth node d for the pixel's view (bilinear in direction), at the group's wavelengths
// or in rgb mode at the three RGB wavelengths.
fn uw_j_node(table: u32, d: u32, group: u32, rgb: bool) -> vec4<f32> {
    var j = vec4<f32>(0.0);
    for (var c = 0u; c < 4u; c++) {
        j += uw_cw[c] * uw_tab(table, UW_L_J + d * UW_NV + uw_cell[c], group, rgb);
    }
    return j;
}

fn uw_ed_node(table: u32, d: u32, group: u32, rgb: bool) -> vec4<f32> {
    return uw_tab(table, UW_L_ED + d, group, rgb);
}

// What the surface reflects towards the pixel's (upward) view, per unit sun irradiance
// (light_field::LightFieldTable::surface: Fresnel × the light coming up the mirrored view,
// the water's part, plus the sea floor's when `floor`), bilinear in direction like J.
// Over the floor the floored table's water and floor parts; beyond it the bottomless table's
// water, whose mirrored view runs forever.
fn uw_surface_node(group: u32, rgb: bool, floor: bool) -> vec4<f32> {
    var r = vec4<f32>(0.0);
    for (var c = 0u; c < 4u; c++) {
        if (floor) {
            r += uw_cw[c] * (uw_tab(0u, UW_L_SURF + uw_cell[c], group, rgb) + uw_tab(0u, UW_L_SURF_FLOOR + uw_cell[c], group, rgb));
        } else {
            r += uw_cw[c] * uw_tab(1u, UW_L_SURF + uw_cell[c], group, rgb);
        }
    }
    return r;
}

// Decay rate of a column between nodes i and i + 1 (ln-linear interpolation), 0 where either
// end is not positive (light_field::segment_rate).
fn uw_rate(a: vec4<f32>, b: vec4<f32>, i: u32) -> vec4<f32> {
    let ok = (a > vec4<f32>(0.0)) & (b > vec4<f32>(0.0));
    let dz = uw_depth_node(i + 1u) - uw_depth_node(i);
    return select(vec4<f32>(0.0), log(max(a, vec4<f32>(1e-30)) / max(b, vec4<f32>(1e-30))) / dz, ok);
}

// ∫ J(z(t), view)·e^{−c·t} dt along the view ray, exponential in depth within each piece and
// integrated in closed form (CPU reference: light_field::ray_integral).
// Consecutive pieces share a node (going down piece p ends at the node where p + 1 starts, going
// up it starts where p + 1 ends), so the last piece's two nodes are kept: one table read of four
// directions per piece instead of two, where the table does not change between them.
fn uw_table_integral(c: vec4<f32>, group: u32, rgb: bool, wy: f32) -> vec4<f32> {
    var sum = vec4<f32>(0.0);
    // Keys (table · 1024 + node) of the previous piece's ends, and their values.
    var key_a = 0xffffffffu;
    var key_b = 0xffffffffu;
    var prev_a = vec4<f32>(0.0);
    var prev_b = vec4<f32>(0.0);
    for (var p = 0u; p < uw_np; p++) {
        let i = uw_pn[p];
        let ka = uw_pd[p] * 1024u + i;
        var ja: vec4<f32>;
        var jb: vec4<f32>;
        if (ka == key_b) {
            ja = prev_b;
        } else {
            ja = uw_j_node(uw_pd[p], i, group, rgb);
        }
        if (ka + 1u == key_a) {
            jb = prev_a;
        } else {
            jb = uw_j_node(uw_pd[p], i + 1u, group, rgb);
        }
        key_a = ka;
        key_b = ka + 1u;
        prev_a = ja;
        prev_b = jb;
        // Below the table the field never grows with depth, from the last node on
        // (light_field::beyond_rate). Selects rather than a branch: one exponential where a
        // CPU driver, running both sides of a branch, evaluated two.
        let beyond = ((uw_beyond >> p) & 1u) != 0u;
        let k0 = uw_rate(ja, jb, i);
        let k = select(k0, max(k0, vec4<f32>(0.0)), beyond);
        let z_from = select(0.0, uw_depth_node(i + 1u) - uw_depth_node(i), beyond);
        // J at the piece's start and the view's attenuation up to it, in one exponential.
        let j0 = select(ja, jb, beyond) * exp(-k * (uw_pz[p] - z_from) - c * uw_pt[p]);
        let infinite = uw_pl[p] < 0.0;
        // A ray to infinity needs c − k·ω_y > 0; the deep field decays, so this only guards noise.
        let rate = select(c - k * wy, max(c - k * wy, 1e-3 * c), infinite);
        sum += j0 * uw_integral_to(rate, uw_pl[p], infinite);
    }
    return sum;
}

// The table's in-scattering for every sun (the table is per unit sun irradiance and already
// holds the sky, so the sky stand-ins add nothing here; other suns reuse the first one's
// table, a documented approximation).
fn uw_table_in_scatter(c: vec4<f32>, group: u32, rgb: bool, wy: f32) -> mat3x4<f32> {
    return s3_scale(uw_suns(group, rgb), uw_table_integral(c, group, rgb, wy));
}

// The pixel's cells, weights and depth segment in the irradiance table: the same for every
// group, so found once per pixel by `uw_prepare_irradiance` (`uw_irradiance` is called per group).
var<private> uw_irr_cells: vec4<u32>;
var<private> uw_irr_w: vec4<f32>;
var<private> uw_irr_i: u32;

// The irradiance table's cells for a surface at depth z facing n.
fn uw_prepare_irradiance(z: f32, n: vec3<f32>) {
    let hn = vec3<f32>(n.x, 0.0, n.z);
    let fe = uw_angle(length(hn), n.y) / 3.14159265358979 * f32(UW_NNE - 1u);
    let fk = uw_sun_azimuth(hn) / 3.14159265358979 * f32(UW_NNA - 1u);
    let cell = uw_cells(fe, fk, UW_NNE, UW_NNA);
    uw_irr_cells = cell.index;
    uw_irr_w = cell.w;
    uw_irr_i = uw_segment(z);
}

// The diffuse irradiance per unit sun E⊥ on the pixel's surface at depth z (the cells of
// `uw_prepare_irradiance`), bilinear in the normal's polar angle and azimuth to the sun,
// ln-linear in depth (CPU reference: light_field::LightFieldTable::irradiance_at).
// `view`: an optical depth the result is attenuated by (e^{−view}), taken into the
// interpolation's exponential.
fn uw_irradiance(table: u32, z: f32, group: u32, rgb: bool, view: vec4<f32>) -> vec4<f32> {
    let cells = uw_irr_cells;
    let w = uw_irr_w;
    let i = uw_irr_i;
    var a = vec4<f32>(0.0);
    var b = vec4<f32>(0.0);
    for (var c = 0u; c < 4u; c++) {
        a += w[c] * uw_tab(table, UW_L_IRR + i * UW_NNE * UW_NNA + cells[c], group, rgb);
        b += w[c] * uw_tab(table, UW_L_IRR + (i + 1u) * UW_NNE * UW_NNA + cells[c], group, rgb);
    }
    return uw_log_interp(a, b, i, z, view);
}

// Between depth nodes i and i + 1 with values a and b, ln-linear at depth z; below the table
// never growing, from the last node on (light_field::log_interp). One exponential, where the
// two sides of a branch were two for a CPU driver.
// `view`: an optical depth to attenuate the result by, in the same exponential.
fn uw_log_interp(a: vec4<f32>, b: vec4<f32>, i: u32, z: f32, view: vec4<f32>) -> vec4<f32> {
    let k = uw_rate(a, b, i);
    let beyond = z > UW_ZMAX;
    let kk = select(k, max(k, vec4<f32>(0.0)), beyond);
    let z_from = select(uw_depth_node(i), UW_ZMAX, beyond);
    return select(a, b, beyond) * exp(-kk * (z - z_from) - view);
}

// The diffuse irradiance of every sun's column on the pixel's surface, as it reaches the
// camera (× e^{−c·d}), in weighted form.
fn uw_surface_irradiance(b: vec4<f32>, c: vec4<f32>, group: u32, rgb: bool, ctx: SurfaceContext) -> mat3x4<f32> {
    let z0 = uw_params().depth;
    let zs = max(z0 - uw_d * ctx.view_dir.y, 0.0);
    let hit = ctx.origin + ctx.view_dir * ctx.distance;
    let cv = c - UW_FWD * b;
    let e = uw_irradiance(select(1u, 0u, uw_over_floor(hit)), zs, group, rgb, cv * uw_d);
    return s3_scale(uw_suns(group, rgb), e);
}

fn custom_light_surface(li: u32, ctx: SurfaceContext) -> f32 {
    // The sky stand-ins' light is in the column's irradiance.
    return select(1.0, 0.0, UW_IRRADIANCE && lights[li].cone.z > 0.5);
}

fn custom_irradiance(lambda: vec4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    if (!UW_IRRADIANCE) { return UW_ZERO; }
    return uw_surface_irradiance(custom_spectra[group * 4u + 0u], custom_spectra[group * 4u + 1u], group, false, ctx);
}

fn custom_irradiance_rgb(ctx: SurfaceContext) -> vec3<f32> {
    if (!UW_IRRADIANCE) { return vec3<f32>(0.0); }
    let b = vec4<f32>(uw_params().b_rgb, 1.0);
    return uw_surface_irradiance(b, vec4<f32>(uw_params().c_rgb, 1.0), 0u, true, ctx)[0].rgb;
}

// E_d(z)/E_d source at depth z, ln-linear between nodes (light_field::log_interp).
// `view`: as `uw_log_interp`'s.
fn uw_table_attenuation(table: u32, z: f32, group: u32, rgb: bool, view: vec4<f32>) -> vec4<f32> {
    let i = uw_segment(z);
    let a = uw_ed_node(table, i, group, rgb);
    let b = uw_ed_node(table, i + 1u, group, rgb);
    return uw_log_interp(a, b, i, z, view);
}

// The lights that get single scattering, at most UW_SS_LIGHTS of those that can (suns, not
// the sky stand-ins, and point, spot and polygon lights), 0xffffffff for an empty slot: all of
// them when they are that few, else the brightest as seen from the camera — a sun by its
// irradiance, any other light by its intensity at its distance, attenuated by the clearest
// water's c over it (so a lamp inside the scene is not dropped for being fifth). The same for
// every pixel (a set that changed from pixel to pixel would draw seams).
fn uw_marched_lights(cam: vec3<f32>) -> vec4<u32> {
    // No more lights than slots: every one that can scatter does (the caller skips the others
    // as the ranking below would), without the ranking's loop in every pixel.
    if (frame.n_lights <= UW_SS_LIGHTS) {
        return vec4<u32>(0u, 1u, 2u, 3u);
    }
    var index = vec4<u32>(0xffffffffu);
    var score = vec4<f32>(-1.0);
    let scale = uw_params().scale;
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        var s = dot(lights[li].rgb.rgb, vec3<f32>(0.2126729, 0.7151522, 0.0721750));
        if (u32(l.w) == 0u) {
            if (-l.y <= 0.0 || lights[li].cone.z > 0.5) { continue; }
        } else {
            let r = length(select(l.xyz, polygon_centroid(li), u32(l.w) == 3u) - cam) * scale;
            s *= exp(-uw_params().c_min * r) / max(r * r, 1e-4);
        }
        // Into the slot of the dimmest kept light, if brighter (the first of equals stays).
        let low = min(min(score.x, score.y), min(score.z, score.w));
        if (s > low) {
            var k = 3u;
            for (var j = 0u; j < 4u; j++) {
                if (score[j] == low) { k = j; break; }
            }
            index[k] = li;
            score[k] = s;
        }
    }
    return index;
}

fn custom_prepare(ctx: SurfaceContext) {
    uw_prepare(ctx);
    if (UW_IRRADIANCE && !ctx.background) {
        uw_prepare_irradiance(max(uw_params().depth - uw_d * ctx.view_dir.y, 0.0), ctx.normal);
    }
}

fn uw_prepare(ctx: SurfaceContext) {
    let z0 = uw_params().depth;
    let scale = uw_params().scale;
    let g = uw_params().g;
    let w = ctx.view_dir;
    uw_infinite = ctx.background && w.y <= 0.0;
    if (ctx.background) {
        // Nothing hit: an upward ray ends at the surface, any other runs forever.
        uw_d = select(0.0, z0 / w.y, w.y > 0.0);
    } else {
        uw_d = ctx.distance * scale;
    }
    if (UW_TABLE) {
        uw_org = ctx.origin;
        uw_view = w;
        uw_prepare_table(w, z0);
    }
    let m = min(u32(uw_params().steps), UW_MAX_STEPS);
    uw_steps = m;
    if (!UW_MARCH || m == 0u) { return; }
    let fm = f32(m);
    let cam = ctx.origin;
    let marched = uw_marched_lights(cam);
    var n = 0u;
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        if (n == UW_SS_LIGHTS) { break; }
        if (!any(marched == vec4<u32>(li))) { continue; }
        let l = lights[li].pos_kind;
        if (u32(l.w) == 0u) {
            // Beam towards the light: its optical path to a point at depth z is c·z/μ. Sky
            // stand-ins are diffuse light, left to `uw_in_scatter`.
            let mu = -l.y;
            if (mu <= 0.0 || lights[li].cone.z > 0.5) { continue; }
            let q = 1.0 - w.y / mu;
            let dm = select(uw_d, UW_CAP / uw_params().c_min, uw_infinite);
            let dt = dm / fm;
            let p = medium_hg(g, dot(-l.xyz, w));
            var lit = true;
            for (var k = 0u; k < m; k++) {
                let x = cam + w * ((f32(k) + 0.5) * dt / scale);
                let v = light_visibility(li, x, vec3<f32>(0.0));
                lit = lit && v >= 1.0;
                uw_w[n * UW_MAX_STEPS + k] = p * v;
            }
            uw_s[n * UW_MAX_STEPS] = z0 / mu;
            uw_lit[n] = lit;
            let tail = select(0.0, p, uw_infinite);
            uw_dir[n] = vec4<f32>(q, dt, tail, z0 / mu + dm * q);
        } else {
            // Equiangular steps (medium_common.wgsl).
            // The march ends after UW_CAP optical depths of the clearest wavelength; what
            // lies beyond is lost (< e^{−6} of the light's scattering there).
            let cap = UW_CAP / uw_params().c_min;
            let dm = select(min(uw_d, cap), cap, uw_infinite);
            let eq = medium_equiangular(l.xyz - cam, w, dm / scale, m);
            for (var k = 0u; k < m; k++) {
                let st = medium_equiangular_step(eq, k);
                let t = st.x;
                let x = cam + w * t;
                let inc = light_incidence(li, x);
                let v = light_visibility(li, x, vec3<f32>(0.0));
                uw_w[n * UW_MAX_STEPS + k] = scale * medium_hg(g, dot(inc.xyz, w)) * v * inc.w * st.z;
                uw_s[n * UW_MAX_STEPS + k] = scale * (st.y + t);
                uw_tv[n * UW_MAX_STEPS + k] = scale * t;
            }
            uw_dir[n] = vec4<f32>(0.0);
        }
        uw_light[n] = li;
        n++;
    }
    uw_n = n;
}

// Single scattering of every marched light, at the wavelengths of `c`; the scattered light
// travels to the camera with `cv` (c − f·b), the light to the scattering point with c.
fn uw_single_scatter(b: vec4<f32>, c: vec4<f32>, cv: vec4<f32>, group: u32, rgb: bool) -> mat3x4<f32> {
    var total = UW_ZERO;
    let dc = c - cv;
    for (var j = 0u; j < uw_n; j++) {
        var sum = vec4<f32>(0.0);
        let dir = uw_dir[j];
        let base = j * UW_MAX_STEPS;
        if (dir.y > 0.0 && uw_lit[j]) {
            // Directional, nothing in the way: the whole ray in closed form.
            let cq = c * dir.x - dc;
            sum = uw_w[base] * exp(-c * uw_s[base]) * uw_ray_integral(cq);
        } else if (dir.y > 0.0) {
            // Directional: the optical path grows by dt·q per segment, so the attenuations
            // form a geometric sequence (two exponentials per group instead of one per step);
            // each segment's exponential is integrated exactly, the tail unshadowed.
            let cq = c * dir.x - dc;
            let ratio = exp(-cq * dir.y);
            var att = exp(-c * uw_s[base]);
            for (var k = 0u; k < uw_steps; k++) {
                sum = fma(vec4<f32>(uw_w[base + k]), att, sum);
                att *= ratio;
            }
            sum = sum * medium_path_integral(cq, dir.y);
            if (dir.z > 0.0) {
                // The tail starts dir.y·steps metres along the view.
                sum += dir.z * exp(-c * dir.w + dc * (dir.y * f32(uw_steps))) / cq;
            }
        } else {
            for (var k = 0u; k < uw_steps; k++) {
                sum = fma(vec4<f32>(uw_w[base + k]), exp(-c * uw_s[base + k] + dc * uw_tv[base + k]), sum);
            }
        }
        total += s3_scale(uw_emission(uw_light[j], group, rgb), b * sum);
    }
    return total;
}

// Isotropic in-scattering of the downwelling field E0·e^{−Kd·z} (the paper's L_ms, whose
// source is the plane irradiance). With `uw_params().gershun` = 1 the source is the scalar
// irradiance instead, from Gershun's law a·E_o = Kd·E_net: E_o = (Kd/a)·E0·e^{−Kd·z}
// (upwelling light neglected, Kd/a ≥ 1). With `uw_params().split_beams` = 1 (and single
// scattering on) the unscattered sun beams inside the field (scalar irradiance
// E_j·e^{−c·z/μ_j}, plane E_j·μ_j·e^{−c·z/μ_j}) are taken out, since `uw_single_scatter`
// counts them with the real phase function; by default single scattering is added on top,
// as the paper's term stands for light scattered many times. Sky stand-ins are diffuse light
// and are never taken out.
// For a ray with vertical component `wy` from depth `z0` over `d` metres (or forever).
fn uw_in_scatter(b: vec4<f32>, c: vec4<f32>, kd: vec4<f32>, group: u32, rgb: bool, wy: f32, z0: f32, d: f32, infinite: bool) -> mat3x4<f32> {
    let gershun = uw_params().gershun > 0.5;
    let split = uw_steps > 0u && uw_params().split_beams > 0.5;
    // k = c + Kd·cosθ with cosθ = −ω_y: the field's decay along the ray, the same for every
    // light; Gershun's factor likewise.
    var field = b * UW_INV_4PI * exp(-kd * z0) * uw_integral_to(c - kd * wy, d, infinite);
    if (gershun) {
        field *= max(kd / max(c - b, vec4<f32>(1e-6)), vec4<f32>(1.0));
    }
    var total = UW_ZERO;
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        let mu = -l.y;
        if (u32(l.w) != 0u || mu <= 0.0) { continue; }
        var f = field * mu;
        if (split && lights[li].cone.z < 0.5) {
            let scalar = select(mu, 1.0, gershun);
            let beam = scalar * exp(-c * (z0 / mu)) * uw_integral_to(c * (1.0 - wy / mu), d, infinite);
            // Per light (not over the sum of lights): a beam larger than its field is clamped.
            f = max(f - b * UW_INV_4PI * beam, vec4<f32>(0.0));
        }
        total += s3_scale(uw_emission(li, group, rgb), f);
    }
    return total;
}

// Unpolarised Fresnel reflectance of the surface for light going up at cosine `cos_w`
// (scene::water::fresnel::fresnel_reflectance with n_i = UW_N, n_t = 1); 1 outside the window.
fn uw_fresnel_up(cos_w: f32) -> f32 {
    let sin_t = UW_N * sqrt(max(1.0 - cos_w * cos_w, 0.0));
    if (sin_t >= 1.0) { return 1.0; }
    let cos_t = sqrt(1.0 - sin_t * sin_t);
    let rs = (UW_N * cos_w - cos_t) / (UW_N * cos_w + cos_t);
    let rp = (cos_w - UW_N * cos_t) / (cos_w + UW_N * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// The surface seen from below at the end of an upward view ray (before the path's
// attenuation): the sky through Snell's window, L_air·T·n² with L_air = E_sky/(π·T̄) from the
// sky stand-ins' irradiance, plus the reflected water below (the in-scattering of a downward
// ray from the surface along the mirrored direction; no sea floor, no single scattering).
fn uw_surface_from_below(b: vec4<f32>, c: vec4<f32>, kd: vec4<f32>, group: u32, rgb: bool, wy: f32, floor: bool) -> mat3x4<f32> {
    let r = uw_fresnel_up(wy);
    var sky = UW_ZERO;
    for (var li = 0u; li < min(frame.n_lights, UW_MAX_LIGHTS); li++) {
        let l = lights[li].pos_kind;
        if (u32(l.w) == 0u && lights[li].cone.z > 0.5 && l.y < 0.0) {
            sky += uw_emission(li, group, rgb) * (-l.y);
        }
    }
    let window = sky * ((1.0 - r) * UW_N * UW_N * UW_SKY_NORM);
    if (UW_TABLE) {
        return window + s3_scale(uw_suns(group, rgb), uw_surface_node(group, rgb, floor));
    }
    return window + uw_in_scatter(b, c, kd, group, rgb, -wy, 0.0, 0.0, true) * r;
}

fn uw_shade(radiance: mat3x4<f32>, b: vec4<f32>, c: vec4<f32>, kd: vec4<f32>, group: u32, rgb: bool, ctx: SurfaceContext) -> mat3x4<f32> {
    let wy = ctx.view_dir.y;
    let z0 = uw_params().depth;
    // Along the view: c minus the forward cone's scattering (light-field model; = c otherwise).
    let cv = c - UW_FWD * b;
    var l: mat3x4<f32>;
    if (UW_TABLE) {
        l = uw_table_in_scatter(cv, group, rgb, wy);
    } else {
        l = uw_in_scatter(b, c, kd, group, rgb, wy, z0, uw_d, uw_infinite);
    }
    if (UW_MARCH) {
        l += uw_single_scatter(b, c, cv, group, rgb);
    }
    if (UW_SURFACE && ctx.background && wy > 0.0) {
        // Where the mirrored view meets the floor's plane (the table ends at the floor, UW_ZMAX
        // m deep): up z0/ω_y metres to the surface, down UW_ZMAX/ω_y to the floor.
        let hw = vec2<f32>(ctx.view_dir.x, ctx.view_dir.z) * ((z0 + UW_ZMAX) / (wy * uw_params().scale));
        let p = vec2<f32>(ctx.origin.x, ctx.origin.z) + hw;
        let on_floor = all(p >= uw_floor_box().xy) && all(p <= uw_floor_box().zw);
        l += s3_scale(uw_surface_from_below(b, c, kd, group, rgb, wy, on_floor), exp(-cv * uw_d));
    }
    if (!ctx.background) {
        let zs = max(z0 - uw_d * wy, 0.0);
        // The light's attenuation down to the surface and the view's back to the camera, in one
        // exponential.
        let view = cv * uw_d;
        var att = exp(-kd * zs - view);
        if (UW_IRRADIANCE) {
            // The lights' direct light: the sun's unscattered beam (other lights get the same
            // factor, as they got Kd's before). The diffuse light comes from `custom_irradiance`.
            att = exp(-c * (zs / max(uw_sun_mu, 1e-3)) - view);
        } else if (UW_TABLE_KD) {
            let hit = ctx.origin + ctx.view_dir * ctx.distance;
            att = uw_table_attenuation(select(1u, 0u, uw_over_floor(hit)), zs, group, rgb, view);
        }
        l += s3_scale(radiance, att);
    }
    return l;
}

fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    let b = custom_spectra[group * 4u + 0u];
    let c = custom_spectra[group * 4u + 1u];
    let kd = custom_spectra[group * 4u + 2u];
    return uw_shade(radiance, b, c, kd, group, false, ctx);
}

fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> {
    // The unused fourth lane gets harmless positive coefficients.
    let c = vec4<f32>(uw_params().c_rgb, 1.0);
    let kd = vec4<f32>(uw_params().kd_rgb, 1.0);
    let b = vec4<f32>(uw_params().b_rgb, 1.0);
    let r = mat3x4<f32>(vec4<f32>(radiance, 0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    return uw_shade(r, b, c, kd, 0u, true, ctx)[0].rgb;
}

