//! Diagnosis of one colour's cell: `cargo run --release -p color --example cell_probe -- SPACE
//! TABLE.coeff R G B`. Prints the colour's ΔE2000 through the table (direct fetch and the
//! shipping fetch), then each corner node of its cell: colour, whether it lies inside the
//! object-colour solid, and how far the table misses it.
use color::delta_e::ciede2000;
use color::upsample::adversarial::ObjectSolid;
use color::upsample::fit::LabModel;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let space = color::RgbColorSpace::by_name(&a[1])?;
    let t = color::upsample::CoeffTable::read(std::path::Path::new(&a[2]))?;
    let rgb: [f64; 3] = [a[3].parse()?, a[4].parse()?, a[5].parse()?];
    let model = LabModel::new(&space)?;
    let solid = ObjectSolid::new(&model);
    let de = |rgb: [f64; 3], c: [f64; 3]| ciede2000(model.target_lab(rgb), model.lab_of_nm(c));
    let direct = t.fetch_direct(rgb.map(|v| v as f32)).c;
    println!("rgb {rgb:?}: fetch ΔE {:.4}, direct ΔE {:.4}", de(rgb, t.fetch(rgb).c), de(rgb, direct));
    let mut l = 0;
    for c in 1..3 {
        if rgb[c] >= rgb[l] {
            l = c;
        }
    }
    let z = rgb[l] as f32;
    let (x, y) = ((rgb[(l + 1) % 3] as f32) / z, (rgb[(l + 2) % 3] as f32) / z);
    let cell = |v: f32, ax: &[f32]| ax.partition_point(|&c| c <= v).clamp(1, t.res - 1) - 1;
    let (xi, yi, zi) = (cell(x, &t.chroma), cell(y, &t.chroma), cell(z, &t.scale));
    println!("table l {l}, cell k {zi} j {yi} i {xi}; ratios x {x:.4} y {y:.4}");
    for c in 0..8 {
        let (i, j, k) = (xi + (c & 1), yi + (c >> 1 & 1), zi + (c >> 2 & 1));
        let zz = t.scale[k] as f64;
        let mut n = [0.0; 3];
        n[l] = zz;
        n[(l + 1) % 3] = t.chroma[i] as f64 * zz;
        n[(l + 2) % 3] = t.chroma[j] as f64 * zz;
        let node = t.node(l, k, j, i).map(|v| v as f64);
        println!(
            "  node k{k} j{j} i{i} rgb ({:.4}, {:.4}, {:.4}) solid margin {:+.2e} node ΔE {:.4} c {:?}",
            n[0],
            n[1],
            n[2],
            solid.margin(n),
            de(n, node),
            node
        );
    }
    Ok(())
}
