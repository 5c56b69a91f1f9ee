//! EXRs whose data window is not their display window, as other tools write them (pbrt-v4's and
//! Blender's crops, Nuke's overscan, a display window away from the origin): the pixels are
//! compared where they lie in the frame. Before, the data window was taken as the image and its
//! place ignored, so two 8×8 crops from different places of one frame were compared pixel for
//! pixel without a word (found by a sweep of files written with the OpenEXR Python package).

use compare::{CompareError, Image, Placement, Region, align, decode_image_placed};
use exr::prelude::*;

/// The frame's pixel (x, y), counted from the display window's top-left.
fn pixel(x: i64, y: i64) -> [f32; 3] {
    [x as f32 * 0.05 + 0.01, y as f32 * 0.07 + 0.02, (x * y).rem_euclid(7) as f32 / 7.0 + 0.05]
}

/// An EXR whose display window is `display` (position, size) and whose data window holds
/// `size` pixels from `origin` (relative to the display window's top-left), each `pixel`.
fn exr(display: ((i32, i32), (usize, usize)), origin: (i32, i32), size: (usize, usize)) -> Vec<u8> {
    let (dp, ds) = display;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = pixel(x as i64 + i64::from(origin.0), y as i64 + i64::from(origin.1));
        (p[0], p[1], p[2])
    });
    let mut layer = Layer::new(size, LayerAttributes::named("rgb"), Encoding::SMALL_LOSSLESS, channels);
    layer.attributes.layer_position = Vec2(dp.0 + origin.0, dp.1 + origin.1);
    let image = exr::prelude::Image::new(
        ImageAttributes::new(IntegerBounds::new(Vec2(dp.0, dp.1), Vec2(ds.0, ds.1))),
        layer,
    );
    let mut out = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut out).unwrap();
    out.into_inner()
}

fn read(bytes: &[u8]) -> (Image, Placement) {
    decode_image_placed("w.exr", bytes).unwrap()
}

/// Every pixel of `im` is the frame's pixel at `origin` + its own position.
fn holds(im: &Image, origin: (i64, i64)) {
    for y in 0..im.height {
        for x in 0..im.width {
            assert_eq!(im.get(x, y), pixel(origin.0 + i64::from(x), origin.1 + i64::from(y)), "({x}, {y})");
        }
    }
}

#[test]
fn data_windows_are_placed_in_their_frame() {
    // The display window away from the origin, and at a negative one: positions count from it.
    for dp in [(0, 0), (-8, -6), (100, 50)] {
        let frame = (dp, (16, 12));
        let (full, fp) = read(&exr(frame, (0, 0), (16, 12)));
        assert_eq!(fp, Placement::whole((16, 12)));
        let (crop_a, ap) = read(&exr(frame, (4, 2), (8, 8)));
        assert_eq!(ap, Placement { frame: (16, 12), origin: (4, 2), size: (8, 8) });
        holds(&crop_a, (4, 2)); // the data window alone, as before; the placement says where it lies
        let (crop_b, bp) = read(&exr(frame, (0, 0), (8, 8)));
        let (over, op) = read(&exr(frame, (-2, -2), (20, 16)));
        assert_eq!(op.origin, (-2, -2));

        // A crop against the full frame: the crop's pixels of the frame.
        let (r, t, region) = align(full.clone(), fp, crop_a.clone(), ap).unwrap();
        assert_eq!(region, Some(Region { frame: (16, 12), origin: (4, 2), size: (8, 8) }));
        assert_eq!(r, t);
        holds(&r, (4, 2));
        let (r, t, _) = align(crop_a.clone(), ap, full.clone(), fp).unwrap();
        assert_eq!(r, t);

        // Two crops of one size at different places: only the 4×6 pixels both hold (these were
        // compared pixel for pixel, (4, 2) with (0, 0)).
        let (r, t, region) = align(crop_a.clone(), ap, crop_b.clone(), bp).unwrap();
        assert_eq!(region, Some(Region { frame: (16, 12), origin: (4, 2), size: (4, 6) }));
        assert_eq!(r, t);
        holds(&r, (4, 2));

        // Overscan against the frame: the frame's pixels.
        let (r, t, region) = align(over.clone(), op, full.clone(), fp).unwrap();
        assert_eq!(region, Some(Region { frame: (16, 12), origin: (0, 0), size: (16, 12) }));
        assert_eq!(r, t);
        holds(&r, (0, 0));

        // The same placement on both sides: as they are.
        let (r, t, region) = align(crop_a.clone(), ap, crop_a.clone(), ap).unwrap();
        assert_eq!((region, r.size(), t.size()), (None, (8, 8), (8, 8)));
    }
}

#[test]
fn images_that_cannot_be_lined_up_are_refused() {
    let frame = ((0, 0), (16, 12));
    let (full, fp) = read(&exr(frame, (0, 0), (16, 12)));
    // The same 16×12 pixels at (3, 2) of a larger frame: another framing.
    let (shifted, sp) = read(&exr(((0, 0), (22, 16)), (3, 2), (16, 12)));
    let e = align(full.clone(), fp, shifted, sp).unwrap_err();
    assert!(matches!(e, CompareError::Misplaced(_)));
    let e = e.to_string();
    assert!(
        e.contains("whole of a 16×12 frame") && e.contains("16×12 pixels at (3, 2) of a 22×16 frame"),
        "{e}"
    );
    // Crops that share no pixel.
    let (a, ap) = read(&exr(frame, (0, 0), (8, 6)));
    let (b, bp) = read(&exr(frame, (8, 6), (8, 6)));
    let e = align(a, ap, b, bp).unwrap_err().to_string();
    assert!(e.contains("share no pixel"), "{e}");
    // Whole images of different sizes are left to the comparison's size check.
    let (small, smp) = read(&exr(((0, 0), (14, 10)), (0, 0), (14, 10)));
    let (r, t, region) = align(full, fp, small, smp).unwrap();
    assert_eq!((region, r.size(), t.size()), (None, (16, 12), (14, 10)));
}
