//! Meshes larger than the device's `max_buffer_size` are split over several vertex/index
//! buffers (issue 14: a 2-million-triangle mesh used to panic in wgpu). The split is exercised
//! here on a small scene by lowering the limit; the image must not change.

mod common;

#[test]
fn a_mesh_split_over_many_buffers_renders_the_same() {
    let mut r = common::renderer();
    // The Cornell box with a faceted sphere of 20 000 triangles (60 000 vertices, 4.3 MB).
    let scene = scene::builtin("dense:20000").unwrap();
    let settings = render::RenderSettings::default();
    r.resize(96, 96).unwrap();
    let mut image = |limit: Option<u64>| {
        match limit {
            Some(bytes) => r.set_scene_with_buffer_limit(&scene, bytes).unwrap(),
            None => r.set_scene(&scene).unwrap(),
        }
        r.render(&scene.camera, &settings).unwrap();
        (r.read_hdr().unwrap(), r.scene_buffer_count())
    };
    let (whole, one) = image(None);
    assert_eq!(one, 1);
    // 64 KiB: 910 vertices a buffer, so the sphere alone takes 66 buffers, cut mid-mesh.
    let (split, many) = image(Some(64 << 10));
    assert!(many >= 66, "{many} buffers");
    let diff = whole
        .iter()
        .zip(&split)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0, f32::max);
    assert!(diff < 1e-3, "largest difference {diff}");
    let lit = whole.iter().filter(|p| p[1] > 0.0).count();
    assert!(lit > whole.len() / 4, "{lit} lit pixels");
}
