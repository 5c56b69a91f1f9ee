//! docs/limits.md's table of numeric options against the command line itself (issue 29): every
//! option of every command that takes a number (found by asking clap's own parser, so an option
//! added later is found too) has a row, the row names the commands that have it, and the bounds
//! the code enforces are the ones the table states.

use clap::CommandFactory;
use std::collections::{BTreeMap, BTreeSet};

/// Options whose value is a number written as text of its own syntax (parsed by the command).
const TEXT_NUMBERS: &[&str] =
    &["size", "range", "wavelengths", "sweep", "suite-sizes", "depth", "crop", "chunk"];

/// (option, commands) for every numeric option.
fn numeric_options() -> BTreeMap<String, BTreeSet<String>> {
    use clap::builder::ValueParser;
    let numbers = [
        ValueParser::from(clap::value_parser!(f32)).type_id(),
        ValueParser::from(clap::value_parser!(f64)).type_id(),
        ValueParser::from(clap::value_parser!(u32)).type_id(),
        ValueParser::from(clap::value_parser!(u64)).type_id(),
        ValueParser::from(clap::value_parser!(usize)).type_id(),
        ValueParser::from(clap::value_parser!(i32)).type_id(),
        ValueParser::from(clap::value_parser!(i64)).type_id(),
    ];
    let cli = crate::Cli::command();
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for sub in cli.get_subcommands().filter(|s| !s.is_hide_set()) {
        for arg in sub.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            if !arg.get_action().takes_values() {
                continue;
            }
            let ty = arg.get_value_parser().type_id();
            if numbers.contains(&ty) || TEXT_NUMBERS.contains(&long) {
                out.entry(format!("--{long}")).or_default().insert(sub.get_name().to_string());
            }
        }
    }
    out
}

/// The rows of the "Numeric options" table: option → (commands cell, the whole row).
fn doc_rows() -> BTreeMap<String, (String, String)> {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/limits.md")).unwrap();
    let section =
        doc.split("## Numeric options").nth(1).expect("docs/limits.md has a 'Numeric options' section");
    let section = section.split("\n## ").next().unwrap();
    let mut rows = BTreeMap::new();
    for line in section.lines().filter(|l| l.starts_with("| `--")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        for opt in cells[1].split(',').map(|c| c.trim().trim_matches('`')) {
            rows.insert(opt.to_string(), (cells[2].to_string(), line.to_string()));
        }
    }
    rows
}

#[test]
fn every_numeric_option_has_a_row_naming_its_commands() {
    let rows = doc_rows();
    let mut missing = vec![];
    for (opt, cmds) in numeric_options() {
        match rows.get(&opt) {
            None => missing.push(format!("{opt} ({})", cmds.iter().cloned().collect::<Vec<_>>().join(", "))),
            Some((cell, _)) => {
                for c in &cmds {
                    assert!(
                        cell.contains(c.as_str()),
                        "docs/limits.md: the row of {opt} does not name `{c}`: {cell}"
                    );
                }
            }
        }
    }
    assert!(missing.is_empty(), "docs/limits.md has no row for: {}", missing.join("; "));
}

#[test]
fn the_table_states_the_bounds_the_code_enforces() {
    let rows = doc_rows();
    let row = |opt: &str| rows.get(opt).unwrap_or_else(|| panic!("no row for {opt}")).1.clone();
    let has = |opt: &str, text: String| {
        let r = row(opt);
        assert!(r.contains(&text), "docs/limits.md, {opt}: expected '{text}' in {r}");
    };
    let (lo, hi) = compare::flip::PPD_RANGE;
    has("--flip-ppd", format!("{lo}–{hi}"));
    let (lo, hi) = compare::flip::EXPOSURE_RANGE;
    has("--flip-start-exposure", format!("{lo}…{hi}"));
    has("--flip-start-exposure", format!("span ≤ {}", compare::flip::MAX_EXPOSURE_SPAN));
    has("--spectral-bin", format!("≤ {} bins", color::wavelengths::MAX_BINS));
    has("--wavelengths", format!("1–{}", render::settings::MAX_WAVELENGTHS));
    has("--exposure", format!("±{}", render::settings::MAX_EXPOSURE_EV));
    has("--env-intensity", format!("0–{:e}", scene::environment::MAX_INTENSITY));
    has("--env-rotation", format!("±{:e}", scene::environment::MAX_ROTATION_DEGREES));
    has("--env-sun-share", "(0, 1]".into());
    has("--time", format!("0–{:e} s", scene::MAX_ANIMATION_TIME));
    has("--frames", format!("1–{}", crate::cmd::bench::MAX_FRAMES));
    has("--samples", format!("render: 1–{} frames", crate::cmd::render::MAX_SAMPLES));
    has("--warmup", format!("0–{}", crate::cmd::bench::MAX_FRAMES));
    has(
        "--checkpoint-every",
        format!(
            "{}–{:e} s",
            crate::cmd::truth::MIN_CHECKPOINT_SECONDS,
            crate::cmd::truth::MAX_CHECKPOINT_SECONDS
        ),
    );
    has("--sample-offset", format!("+ spp ≤ 2^{}", truth::render::MAX_SAMPLE_INDEX.trailing_zeros()));
    let (lo, hi) = (compare::diff::MIN_WHITE_LUMINANCE, compare::diff::MAX_WHITE_LUMINANCE);
    has("--white-y", format!("{lo:e}…{hi:e}"));
}
