//! Converts between the image formats `compare` reads and writes:
//! `convert IN OUT [--half] [--png16]`.
//!
//! A developer tool and the hook `tools/check_diff_io.py` uses to check our EXR/PNG reader and
//! writer against OpenEXR and libpng (through Mitsuba). `--half` writes f16 EXR, `--png16`
//! 16-bit PNG.

use std::process::ExitCode;

use compare::{ExrPrecision, PngBitDepth, WriteOptions, read_image, write_image};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flags: Vec<&str> = args.iter().filter(|a| a.starts_with("--")).map(String::as_str).collect();
    let paths: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    if paths.len() != 2 || flags.iter().any(|f| !["--half", "--png16"].contains(f)) {
        eprintln!("usage: convert IN OUT [--half] [--png16]");
        return ExitCode::from(2);
    }
    let opts = WriteOptions {
        exr: if flags.contains(&"--half") { ExrPrecision::F16 } else { ExrPrecision::F32 },
        png: if flags.contains(&"--png16") { PngBitDepth::Sixteen } else { PngBitDepth::Eight },
    };
    match read_image(paths[0]).and_then(|im| write_image(paths[1], &im, opts)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
