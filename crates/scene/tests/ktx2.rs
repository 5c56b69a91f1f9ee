//! KHR_texture_basisu: KTX2 / Basis Universal textures, transcoded and compared with the PNG
//! originals they were made from (Khronos sample assets, `tests/data/ktx2/README.md`), loaded
//! through whole glTF files with and without a PNG fallback, and refused with one line naming
//! the image or field when hostile.

use std::path::{Path, PathBuf};

use base64::Engine;
use scene::{Scene, Texture};
use serde_json::{Value, json};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/ktx2")
}

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(data_dir().join(name)).unwrap()
}

fn data_uri(mime: &str, bytes: &[u8]) -> String {
    format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes))
}

fn png_rgba(name: &str) -> (u32, u32, Vec<u8>) {
    let img = image::open(data_dir().join(name)).unwrap().into_rgba8();
    (img.width(), img.height(), img.into_raw())
}

/// A 2×2 PNG, as the PNG fallback in `source` (a size no KTX2 fixture has).
fn tiny_png_uri() -> String {
    let img =
        image::RgbaImage::from_raw(2, 2, vec![255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 9, 9, 9, 255])
            .unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    data_uri("image/png", &out.into_inner())
}

/// One textured triangle whose material uses texture 0 as its base colour (sRGB) and texture 1
/// (default: texture 0 too) as its metallic-roughness texture (linear data). The caller fills in
/// `images`, `textures` and the extension lists.
fn doc() -> Value {
    let mut bytes = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0] {
        bytes.extend(v.to_le_bytes());
    }
    json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0}}}],
        "buffers": [{"byteLength": 60, "uri": data_uri("application/octet-stream", &bytes)}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
        ],
        "extensionsUsed": ["KHR_texture_basisu"],
    })
}

/// A document whose texture 0 is only the KTX2 image `uri`.
fn ktx2_doc(uri: &str) -> Value {
    let mut d = doc();
    d["images"] = json!([{"uri": uri}]);
    d["textures"] = json!([{"extensions": {"KHR_texture_basisu": {"source": 0}}}]);
    d
}

fn load(doc: &Value) -> Result<Scene, String> {
    scene::load_slice("t.gltf", doc.to_string().as_bytes(), Some(&data_dir())).map_err(|e| e.to_string())
}

fn error(doc: &Value) -> String {
    let Err(e) = load(doc) else { panic!("loaded without error") };
    assert!(!e.contains('\n'), "not one line: {e}");
    e
}

fn assert_has(e: &str, parts: &[&str]) {
    for p in parts {
        assert!(e.contains(p), "error lacks '{p}': {e}");
    }
}

fn base_color(s: &Scene) -> &Texture {
    &s.textures[s.materials[0].base_color_texture.as_ref().unwrap().index]
}

fn metallic_roughness(s: &Scene) -> &Texture {
    &s.textures[s.materials[0].metallic_roughness_texture.as_ref().unwrap().index]
}

/// Per-channel PSNR (dB, peak 255) and mean absolute difference of two RGBA8 images of equal
/// size, over the first `channels` channels.
fn compare(a: &[u8], b: &[u8], channels: usize) -> (Vec<f64>, Vec<f64>) {
    assert_eq!(a.len(), b.len());
    let n = (a.len() / 4) as f64;
    (0..channels)
        .map(|c| {
            let (mut se, mut ae) = (0.0, 0.0);
            for (p, q) in a.chunks(4).zip(b.chunks(4)) {
                let d = f64::from(p[c]) - f64::from(q[c]);
                se += d * d;
                ae += d.abs();
            }
            let mse = se / n;
            (10.0 * (255.0 * 255.0 / mse.max(1e-12)).log10(), ae / n)
        })
        .unzip()
}

/// `rgba` (w×h) averaged over k×k blocks, as `make_fixtures.py` made the reference (Pillow's
/// `reduce`, a box filter on the stored values).
fn reduce(w: u32, h: u32, rgba: &[u8], k: u32) -> Vec<u8> {
    let (ow, oh) = (w / k, h / k);
    let mut out = Vec::with_capacity((ow * oh * 4) as usize);
    for y in 0..oh {
        for x in 0..ow {
            for c in 0..4 {
                let mut sum = 0u32;
                for dy in 0..k {
                    for dx in 0..k {
                        sum += u32::from(rgba[(((y * k + dy) * w + x * k + dx) * 4 + c) as usize]);
                    }
                }
                out.push(((sum as f64) / f64::from(k * k)).round() as u8);
            }
        }
    }
    out
}

/// What a decoder that got the colour space wrong would give: sRGB-encoded texels stored as if
/// they were linear (each channel but alpha through the sRGB decoding curve).
fn wrongly_linearised(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks(4)
        .flat_map(|p| {
            let f = |v: u8| (scene::srgb::decode(f64::from(v) / 255.0) * 255.0).round() as u8;
            [f(p[0]), f(p[1]), f(p[2]), p[3]]
        })
        .collect()
}

/// Red and blue swapped (an RGBA/BGRA mix-up).
fn swapped(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks(4).flat_map(|p| [p[2], p[1], p[0], p[3]]).collect()
}

/// PSNR floors, from measurements of these fixtures (the transcoder is bit-exact, so the figures
/// are fixed; README.md lists them). UASTC reproduces the occlusion-roughness-metal map at
/// 40.8 dB in its only varying channel. The ETC1S base colours, compared after box-averaging to
/// 128² (the encoder resized them from 2048² with a filter of its own, which counts too), reach
/// 38.7–47.6 dB (grey hardware) and 35.1–36.5 dB, alpha 51.9 dB (coloured grill). Each floor is
/// 2–3 dB under the worst channel measured and well above what a colour-space mistake (≤ 18.6 dB)
/// or a red–blue swap (≤ 26.6 dB on the coloured images) gives; the tests check that both fail.
const UASTC_MIN_PSNR: f64 = 38.0;
const ETC1S_MIN_PSNR: f64 = 33.0;

fn assert_psnr(what: &str, psnr: &[f64], mad: &[f64], min: f64) {
    eprintln!("{what}: PSNR {psnr:.2?} dB, mean |Δ| {mad:.3?}");
    assert!(psnr.iter().all(|&p| p >= min), "{what}: PSNR {psnr:.2?} dB, below {min} dB");
}

fn assert_fails(what: &str, psnr: &[f64], min: f64) {
    eprintln!("{what} (must fail): PSNR {psnr:.2?} dB");
    assert!(psnr.iter().any(|&p| p < min), "{what} passes the threshold: {psnr:.2?} dB");
}

#[test]
fn basis_textures_match_their_png_originals() {
    // UASTC with Zstandard supercompression (the sample asset as published), and the same
    // payload without supercompression: the texture is linear data (metallic-roughness).
    let (w, h, png) = png_rgba("steel_orm.png");
    let mut decoded = Vec::new();
    for f in ["steel_orm.ktx2", "steel_orm_raw.ktx2"] {
        let s = load(&ktx2_doc(f)).unwrap();
        let t = metallic_roughness(&s);
        assert_eq!((t.width, t.height, t.srgb), (w, h, false), "{f}");
        let (psnr, mad) = compare(&t.rgba8, &png, 3);
        assert_psnr(f, &psnr, &mad, UASTC_MIN_PSNR);
        assert_fails(
            &format!("{f}, red and blue swapped"),
            &compare(&swapped(&t.rgba8), &png, 3).0,
            UASTC_MIN_PSNR,
        );
        assert_fails(
            &format!("{f}, wrongly linearised"),
            &compare(&wrongly_linearised(&t.rgba8), &png, 3).0,
            UASTC_MIN_PSNR,
        );
        decoded.push(t.rgba8.clone());
    }
    assert!(decoded[0] == decoded[1], "the same UASTC blocks decode alike with and without Zstandard");

    // ETC1S (BasisLZ), sRGB colour: an opaque grey 512² and a coloured 1024² with alpha, both from
    // 2048² PNGs, compared at 128² (`reduce`). The grey one cannot tell red from blue; the other
    // can, and its alpha is compared too.
    for (f, size, channels) in [("hardware_basecolor", 512, 3), ("grill_basecolor_alpha", 1024, 4)] {
        let s = load(&ktx2_doc(&format!("{f}.ktx2"))).unwrap();
        let t = base_color(&s);
        assert_eq!((t.width, t.height, t.srgb), (size, size, true), "{f}");
        let small = reduce(size, size, &t.rgba8, size / 128);
        let (rw, rh, reference) = png_rgba(&format!("{f}_128.png"));
        assert_eq!((rw, rh), (128, 128));
        let (psnr, mad) = compare(&small, &reference, channels);
        assert_psnr(&format!("{f}.ktx2 (128²)"), &psnr, &mad, ETC1S_MIN_PSNR);
        let linearised = reduce(size, size, &wrongly_linearised(&t.rgba8), size / 128);
        assert_fails(
            &format!("{f}, wrongly linearised"),
            &compare(&linearised, &reference, 3).0,
            ETC1S_MIN_PSNR,
        );
        if channels == 4 {
            assert_fails(
                &format!("{f}, red and blue swapped"),
                &compare(&swapped(&small), &reference, 3).0,
                ETC1S_MIN_PSNR,
            );
            assert!(t.rgba8.chunks(4).any(|p| p[3] < 128), "{f}: the alpha channel is decoded");
        } else {
            assert!(t.rgba8.chunks(4).all(|p| p[3] == 255), "{f}: an opaque texture decodes opaque");
        }
    }
}

/// The KTX2 image is preferred to the PNG fallback in `source`; a texture may have only the KTX2
/// image; a file may require the extension; a KTX2 given as an ordinary `source` decodes too; a
/// texture with both a WebP and a KTX2 image shows the WebP one (`gltf_ext::IMAGE_EXTENSIONS`).
#[test]
fn ktx2_textures_load_with_and_without_fallback() {
    let (_, _, png) = png_rgba("steel_orm.png");
    let check = |d: &Value| {
        let s = load(d).unwrap();
        let t = metallic_roughness(&s);
        assert_eq!((t.width, t.height), (256, 256), "the KTX2 image, not the 2×2 fallback");
        let (psnr, mad) = compare(&t.rgba8, &png, 3);
        assert_psnr("steel_orm.ktx2 through a glTF", &psnr, &mad, UASTC_MIN_PSNR);
        s
    };
    // With a PNG fallback, only used.
    let mut d = doc();
    d["images"] = json!([{"uri": tiny_png_uri()}, {"uri": "steel_orm.ktx2"}]);
    d["textures"] = json!([{"source": 0, "extensions": {"KHR_texture_basisu": {"source": 1}}}]);
    let s = check(&d);
    // The base colour use of this linear data texture is worth a word.
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    assert_has(&s.warnings[0], &["images[1]", "linear transfer function", "sRGB colour"]);
    // Required.
    d["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    check(&d);
    // Only the KTX2 image, required.
    let mut only = ktx2_doc("steel_orm.ktx2");
    only["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    check(&only);
    // A KTX2 image in a data URI, as a plain source without the extension.
    let mut plain = doc();
    plain["images"] = json!([{"uri": data_uri("image/ktx2", &fixture("steel_orm.ktx2"))}]);
    plain["textures"] = json!([{"source": 0}]);
    check(&plain);
    // Used only as data, the linear KTX2 brings no warning.
    let mut data_only = ktx2_doc("steel_orm.ktx2");
    data_only["materials"][0]["pbrMetallicRoughness"].as_object_mut().unwrap().remove("baseColorTexture");
    assert!(load(&data_only).unwrap().warnings.is_empty());
    // WebP and KTX2 both: the WebP image.
    let mut both = doc();
    let webp = image::RgbaImage::from_raw(1, 1, vec![10, 20, 30, 255]).unwrap();
    let mut out = std::io::Cursor::new(Vec::new());
    webp.write_to(&mut out, image::ImageFormat::WebP).unwrap();
    both["extensionsUsed"] = json!(["KHR_texture_basisu", "EXT_texture_webp"]);
    both["images"] = json!([{"uri": "steel_orm.ktx2"}, {"uri": data_uri("image/webp", &out.into_inner())}]);
    both["textures"] =
        json!([{"extensions": {"KHR_texture_basisu": {"source": 0}, "EXT_texture_webp": {"source": 1}}}]);
    let s = load(&both).unwrap();
    let t = metallic_roughness(&s);
    assert_eq!((t.width, t.height, t.rgba8.as_slice()), (1, 1, &[10, 20, 30, 255][..]));
}

/// The 8×8 UASTC fixture with a change made by `f` (its DFD is at byte 104, level 0 at 160).
fn patched(f: impl Fn(&mut Vec<u8>)) -> Vec<u8> {
    let mut b = fixture("steel_orm_8x8.ktx2");
    f(&mut b);
    b
}

/// The 8×8 fixture with a key/value block holding `key` = `value`.
fn with_key_value(key: &str, value: &str) -> Vec<u8> {
    patched(|b| {
        let mut entry = [key.as_bytes(), b"\0", value.as_bytes(), b"\0"].concat();
        let at = b.len() as u32;
        b.extend((entry.len() as u32).to_le_bytes());
        while entry.len() % 4 != 0 {
            entry.push(0);
        }
        b.extend(&entry);
        let length = b.len() as u32 - at;
        set_u32(b, 56, at);
        set_u32(b, 60, length);
    })
}

fn set_u32(b: &mut [u8], at: usize, v: u32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

fn set_u64(b: &mut [u8], at: usize, v: u64) {
    b[at..at + 8].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn hostile_ktx2_images_are_named_in_one_line() {
    let with = |bytes: &[u8]| ktx2_doc(&data_uri("image/ktx2", bytes));
    // The 8×8 fixture itself loads: what follows is refused for the change made to it.
    let ok = fixture("steel_orm_8x8.ktx2");
    let s = load(&with(&ok)).unwrap();
    assert_eq!((metallic_roughness(&s).width, metallic_roughness(&s).height), (8, 8));

    let cases: Vec<(&str, Vec<u8>, &[&str])> = vec![
        ("truncated in the header", ok[..60].to_vec(), &["images[0]", "ends inside its header"]),
        ("truncated in the data", ok[..ok.len() - 10].to_vec(), &["images[0]", "level 0", "truncated"]),
        ("truncated ETC1S", fixture("hardware_basecolor.ktx2")[..9000].to_vec(), &["images[0]", "truncated"]),
        (
            "100000×100000",
            patched(|b| {
                set_u32(b, 20, 100_000);
                set_u32(b, 24, 100_000);
            }),
            &["images[0]", "100000×100000", "at most 16384"],
        ),
        (
            "not Basis",
            patched(|b| set_u32(b, 12, 43)),
            &["images[0]", "VK_FORMAT_R8G8B8A8_SRGB", "not Basis Universal", "KHR_texture_basisu requires"],
        ),
        ("a cube map", patched(|b| set_u32(b, 36, 6)), &["images[0]", "cube map"]),
        ("an array", patched(|b| set_u32(b, 32, 4)), &["images[0]", "texture array"]),
        ("3D", patched(|b| set_u32(b, 28, 8)), &["images[0]", "3D texture"]),
        (
            "a Zstandard size of 1 TiB",
            patched(|b| {
                set_u32(b, 44, 2);
                set_u64(b, 96, 1 << 40);
            }),
            &["images[0]", "1099511627776 bytes of UASTC data", "8×8 texels take 64"],
        ),
        (
            "a level beyond the file",
            patched(|b| set_u64(b, 80, u64::MAX - 4)),
            &["images[0]", "level 0", "lies outside"],
        ),
        ("an ASTC colour model", patched(|b| b[104 + 12] = 162), &["images[0]", "colour model is 162"]),
        (
            "UASTC under BasisLZ",
            patched(|b| set_u32(b, 44, 1)),
            &["images[0]", "UASTC with supercompression scheme 1", "allows"],
        ),
        (
            "a swizzle",
            with_key_value("KTXswizzle", "bgra"),
            &["images[0]", "KTXswizzle is \"bgra\"", "\"rgba\""],
        ),
        ("flipped", with_key_value("KTXorientation", "ru"), &["images[0]", "KTXorientation is \"ru\""]),
    ];
    for (what, bytes, parts) in cases {
        let e = error(&with(&bytes));
        eprintln!("{what}: {e}");
        assert_has(&e, parts);
    }

    // The values the extension allows are accepted.
    for (k, v) in [("KTXswizzle", "rgba"), ("KTXorientation", "rd")] {
        load(&with(&with_key_value(k, v))).unwrap();
    }

    // The extension's image index.
    let at = "textures[0].extensions.KHR_texture_basisu.source";
    for v in [json!(7), json!(-1), json!("0")] {
        let mut d = ktx2_doc("steel_orm.ktx2");
        d["textures"][0]["extensions"]["KHR_texture_basisu"]["source"] = v;
        assert_has(&error(&d), &[at, "is not the index of one of the file's 1 images"]);
    }
    let mut d = ktx2_doc("steel_orm.ktx2");
    d["textures"][0]["extensions"]["KHR_texture_basisu"] = json!({});
    assert_has(&error(&d), &[at, "is missing", "KTX2 image"]);
    // A missing file is named like any other image's.
    assert_has(&error(&ktx2_doc("nowhere.ktx2")), &["images[0].uri"]);
}

/// Corrupted bytes anywhere in a KTX2 (header, descriptor, codebooks, blocks) come back as an
/// error or a decoded image, never a panic or an abort.
#[test]
fn corrupted_ktx2_images_never_panic() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let sources = [fixture("steel_orm_8x8.ktx2"), fixture("hardware_basecolor.ktx2")];
    let (mut loaded, mut refused) = (0, 0);
    for i in 0..300 {
        let mut b = sources[i % 2].clone();
        for _ in 0..rng.random_range(1..4) {
            let at = rng.random_range(0..b.len());
            b[at] = rng.random();
        }
        if rng.random_bool(0.2) {
            b.truncate(rng.random_range(0..b.len()));
        }
        match load(&ktx2_doc(&data_uri("image/ktx2", &b))) {
            Ok(_) => loaded += 1,
            Err(e) => {
                assert!(!e.contains('\n') && e.contains("images[0]"), "{e}");
                refused += 1;
            }
        }
    }
    eprintln!("{loaded} loaded, {refused} refused");
    assert!(refused > 0);
}

/// The fuzz corpus's KTX2 seed (`make_fixtures.py`) loads, so that the fuzzer's mutations start
/// from a file that reaches the transcoder: both textures 8×8 from the one KTX2 image, the base
/// colour use warned about (the image is linear data).
#[test]
fn the_fuzz_seed_loads() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus/gltf/ktx2-basisu.glb");
    let s = scene::load_slice("ktx2-basisu.glb", &std::fs::read(path).unwrap(), None).unwrap();
    assert_eq!(
        s.textures.iter().map(|t| (t.width, t.height, t.srgb)).collect::<Vec<_>>(),
        [(8, 8, true), (8, 8, false)]
    );
    assert_eq!(s.textures[0].rgba8, s.textures[1].rgba8);
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
}
