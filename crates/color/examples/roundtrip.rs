//! Round trip of a `.coeff` table: `cargo run --release -p color --example roundtrip -- FILE [SPACE] [N]`.
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let t = color::upsample::CoeffTable::read(std::path::Path::new(&a[1]))?;
    let space = color::RgbColorSpace::by_name(a.get(2).map(|s| s.as_str()).unwrap_or("srgb"))?;
    let n = a.get(3).map(|s| s.parse()).transpose()?.unwrap_or(100_000);
    let r = color::upsample::roundtrip::roundtrip_table(&t, &space, n, 1)?;
    println!("{}", serde_json::to_string(&r)?);
    Ok(())
}
