// Screen-space occlusion of ambient light (the environment, a medium's irradiance), shared by
// the occlusion pass (passes/occlusion.rs, occlusion_pass.wgsl), which writes it per pixel
// before the shading, and the shading pass, which searches it itself on the transmissive layer.
// Uses `frame`, `env` and `gbuf_depth` (group 1, binding 3), which each includer declares.

// Screen-space occlusion of the environment at pixel `pix` (world position p, normal n): the
// fraction of the cosine-weighted hemisphere not hidden by what the depth buffer shows within
// `env.params.w` world units. Per screen direction (8, rotated per pixel) the highest horizon
// sin h = max n·v̂ over 6 steps hides sin²h of the slice's cosine-weighted measure (the
// horizon-based estimate of Bavoil et al. 2008 with the cosine weighting of GTAO, Jimenez et al.
// 2016). Environment light arrives from infinity, so an occluder hides it at any distance: no
// distance falloff, only the search radius; samples nearer the camera than p by more than the
// radius are taken for separate objects in front (not occluders).
const OCCLUSION_BIAS: f32 = 0.1;
// Depth-buffer steps (units in the last place of the pixel's depth) that the next pixel must lie
// farther away than for the occlusion to be searched (`env_occlusion`).
const OCCLUSION_DEPTH_STEPS: f32 = 4.0;

// The world position at pixel q; w = 0 on the background (or off screen).
fn position_at(q: vec2<f32>) -> vec4<f32> {
    if (any(q < vec2<f32>(0.0)) || any(q >= frame.viewport.xy)) { return vec4<f32>(0.0); }
    let d = textureLoad(gbuf_depth, vec2<i32>(q), 0);
    if (is_far_depth(d)) { return vec4<f32>(0.0); }
    return vec4<f32>(world_from_depth(floor(q) + 0.5, d, frame), 1.0);
}

// The nearer of two neighbours' offsets from p (the one on this side of any depth edge).
fn nearer_offset(a: vec4<f32>, b: vec4<f32>, p: vec3<f32>) -> vec3<f32> {
    let da = p - a.xyz;
    let db = b.xyz - p;
    if (a.w == 0.0) { return select(vec3<f32>(0.0), db, b.w != 0.0); }
    if (b.w == 0.0) { return da; }
    return select(da, db, dot(db, db) < dot(da, da));
}

// Facets that disagree with the surface's own normal by more than this (cos 60°) were built
// across a depth edge on both sides of an axis, so `depth_normal` keeps the surface's normal:
// a one-pixel-wide object, or a BLEND material's dithered coverage, whose kept pixels have the
// backdrop for neighbours (the facet then lay along the view ray, and the backdrop 1 unit behind
// a frontal quad rose above it: −11 % of the environment's light). Interpolated and mapped normals
// stay well within 60° of their facets, so their pixels keep the facet as before.
const OCCLUSION_FACET_MIN_COS: f32 = 0.5;

// Unit normal of the surface's facet at pixel `pix` from the depth buffer, on the side of `n`.
fn depth_normal(pix: vec2<f32>, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let dx = nearer_offset(position_at(pix - vec2<f32>(1.0, 0.0)), position_at(pix + vec2<f32>(1.0, 0.0)), p);
    let dy = nearer_offset(position_at(pix - vec2<f32>(0.0, 1.0)), position_at(pix + vec2<f32>(0.0, 1.0)), p);
    let c = cross(dx, dy);
    if (dot(c, c) < 1e-20) { return n; }
    let g = normalize(c);
    let facing = select(-g, g, dot(g, n) >= 0.0);
    return select(n, facing, dot(facing, n) >= OCCLUSION_FACET_MIN_COS);
}

fn env_occlusion(pix: vec2<f32>, p: vec3<f32>, n: vec3<f32>) -> f32 {
    let radius = env.params.w;
    if (radius <= 0.0) { return 1.0; }
    let c = frame.view_proj * vec4<f32>(p, 1.0);
    // The search radius on screen: project a point `radius` away from p across the view ray.
    let to_p = p - frame.camera_pos.xyz;
    var across = cross(to_p, vec3<f32>(0.0, 1.0, 0.0));
    if (dot(across, across) < 1e-12 * dot(to_p, to_p)) { across = cross(to_p, vec3<f32>(1.0, 0.0, 0.0)); }
    let c2 = frame.view_proj * vec4<f32>(p + normalize(across) * radius, 1.0);
    let half_px = 0.5 * frame.viewport.xy;
    let screen_r = min(length((c2.xy / c2.w - c.xy / c.w) * half_px), 0.25 * frame.viewport.y);
    if (screen_r < 2.0) { return 1.0; }
    // Horizons need the depth buffer to tell neighbouring pixels apart: where the next pixel
    // lies nearer than a few of its steps along the view ray (an extreme telephoto lens; far
    // from a small near plane), the facets and horizons rebuilt from depth are noise (a convex
    // sphere under a 1e-5 rad field of view lost up to 75 % of its light, in blocks), so the
    // light is left unoccluded there.
    let dp = textureLoad(gbuf_depth, vec2<i32>(pix), 0);
    let along = world_from_depth(pix, max(dp - OCCLUSION_DEPTH_STEPS * dp * 1.1920929e-7, 0.0), frame) - p;
    let side = world_from_depth(pix + vec2<f32>(1.0, 0.0), dp, frame) - p;
    if (dot(side, side) <= dot(along, along)) { return 1.0; }
    // Horizons are measured from the facet's plane, reconstructed from the depth of the nearer
    // neighbour on each axis (interpolated normals tilt off the facets, and on a convex mesh a
    // neighbouring facet would then rise above the tangent plane and count as an occluder).
    let ng = depth_normal(pix, p, n);
    // A new pattern in each accumulated frame, so that the mean converges (frame_index is 0
    // without accumulation).
    let h = hash2_unit(vec2<u32>(pix), 0x0cc10000u + frame.frame_index);
    let hash = h.x;
    let hash2 = h.y;
    var hidden = 0.0;
    let dirs = 8u;
    let steps = 6u;
    let depth_p = length(p - frame.camera_pos.xyz);
    for (var d = 0u; d < dirs; d++) {
        let a = (f32(d) + hash) * (2.0 * PI / f32(dirs));
        let dir = vec2<f32>(cos(a), sin(a));
        var max_sin = 0.0;
        for (var s = 0u; s < steps; s++) {
            let t = (f32(s) + hash2) / f32(steps);
            let q = pix + dir * (1.0 + t * screen_r);
            if (any(q < vec2<f32>(0.0)) || q.x >= frame.viewport.x || q.y >= frame.viewport.y) { break; }
            let depth = textureLoad(gbuf_depth, vec2<i32>(q), 0);
            if (is_far_depth(depth)) { continue; }
            // The depth is that of the texel's centre: placing it at q instead would move the
            // point sideways by up to half a pixel, which at a silhouette, where depth changes
            // fast across the screen, tilts v by tenths of a radian (a convex sphere's rim
            // occluded itself by 1 % in the white furnace).
            let wq = world_from_depth(floor(q) + 0.5, depth, frame);
            let v = wq - p;
            let len = length(v);
            if (len < 1e-6 || len > radius) { continue; }
            if (depth_p - length(wq - frame.camera_pos.xyz) > radius) { continue; }
            // A small angle bias keeps depth-reconstruction noise on convex surfaces (whose
            // neighbours all lie below the tangent plane) from counting as occlusion.
            max_sin = max(max_sin, (dot(ng, v) / len - OCCLUSION_BIAS) / (1.0 - OCCLUSION_BIAS));
        }
        hidden += max_sin * max_sin;
    }
    return 1.0 - hidden / f32(dirs);
}
