//! Interoperability: spectral EXRs written by another writer (the OpenEXR Python package, by
//! tools/check_fichet_exr.py, following Fichet et al. 2021's channel naming with two decimals
//! and no band-edge attribute) are read and integrated by spectra to 1e-4 of colour-science's
//! integration of the same data (fichet_expected.json, written by the same script), shown by
//! the display convention (`color::film`): XYZ scaled so that the white, as integrated on the
//! file's bands, lands on sRGB's white — both whites also from colour-science.

use color::{Observer, RgbColorSpace, illuminant};
use compare::spectral::{SpectralKind, read_spectral_exr};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

#[test]
fn independent_files_integrate_like_colour_science() {
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("fichet_expected.json")).unwrap()).unwrap();
    let d65 = illuminant::by_name("D65").unwrap();
    let srgb = RgbColorSpace::srgb();
    for (kind, want_kind) in [("emissive", SpectralKind::Emissive), ("reflective", SpectralKind::Reflective)]
    {
        let img = read_spectral_exr(data(&format!("fichet_{kind}.exr"))).unwrap();
        assert_eq!((img.width, img.height, img.kind, img.bands()), (4, 3, want_kind, 31));
        // Bands from the wavelengths alone: 10 nm wide, centred on 400 … 700 nm.
        assert_eq!((img.edges[0], img.edges[31]), (395.0, 705.0));
        for obs in ["cie1931", "cie1964"] {
            let rgb = img.to_linear_srgb(&Observer::by_name(obs).unwrap(), &d65).unwrap();
            let want = expected[kind][obs].as_array().unwrap();
            let num = |v: &serde_json::Value, c: usize| v[c].as_f64().unwrap();
            let (white, srgb_white) = (&expected[kind]["white"][obs], &expected["srgb_white"]);
            let mut worst = 0.0f64;
            for (p, w) in rgb.data.iter().zip(want) {
                let xyz = srgb.rgb_to_xyz(p.map(f64::from));
                for (c, got) in xyz.iter().enumerate() {
                    let shown = num(w, c) * num(srgb_white, c) / num(white, c);
                    worst = worst.max((got - shown).abs());
                }
            }
            assert!(worst < 1e-4, "{kind} {obs}: worst |ΔXYZ| {worst:e}");
            eprintln!("{kind} {obs}: worst |ΔXYZ| against colour-science {worst:.2e}");
        }
    }
}
