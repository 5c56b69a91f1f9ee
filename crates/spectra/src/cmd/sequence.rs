//! `spectra render --times`: an animation rendered as a numbered sequence of frames, one per
//! moment, each written as soon as it is drawn (so Ctrl-C keeps the frames finished and
//! `--resume` draws only the missing ones).

use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// The most frames one `--times` asks for (an hour at 24 frames per second is 86 400).
pub const MAX_FRAMES: usize = 100_000;

/// Refuses `--times ARG` for a built-in scene (`scene`: the scene argument): only glTF files
/// have animations. `render` and `truth` share it.
pub fn require_gltf(arg: &str, scene: &str) -> Result<()> {
    let lower = scene.to_ascii_lowercase();
    if !(lower.ends_with(".gltf") || lower.ends_with(".glb")) {
        bail!("--times {arg}: animations belong to glTF files; '{scene}' is a built-in scene");
    }
    Ok(())
}

/// Whether `--times` ends its range at the animation's end (`START:end:STEP`), which only the
/// loaded file knows.
pub fn needs_end(arg: &str) -> bool {
    arg.split(':').nth(1).is_some_and(|e| e.trim().eq_ignore_ascii_case("end"))
}

/// The first moment `--times` names (what a range's `end` is looked up at).
pub fn start(arg: &str) -> Result<f64> {
    let first = arg.split([':', ',']).next().unwrap_or_default().trim();
    first.parse().map_err(|_| anyhow::anyhow!("--times {arg}: '{first}' is not a number of seconds"))
}

/// The moments `--times` names: `START:END:STEP` (seconds; END included when a step lands on
/// it, to a billionth of the step; `end`: `animation_end`, the chosen animation's last key) or
/// a comma list. Each within [0, the loader's largest animation time]; at most [`MAX_FRAMES`].
pub fn parse_times(arg: &str, animation_end: Option<f64>) -> Result<Vec<f64>> {
    let bad = |why: String| anyhow::anyhow!("--times {arg}: {why}");
    let number = |s: &str| -> Result<f64> {
        let v: f64 =
            s.trim().parse().map_err(|_| bad(format!("'{}' is not a number of seconds", s.trim())))?;
        if !(v.is_finite() && (0.0..=scene::MAX_ANIMATION_TIME).contains(&v)) {
            return Err(bad(format!("{v} s is outside 0 … {} s", scene::MAX_ANIMATION_TIME)));
        }
        Ok(v)
    };
    let times = if arg.contains(':') {
        let parts: Vec<&str> = arg.split(':').collect();
        let [a, b, s] = parts[..] else {
            return Err(bad("a range is START:END:STEP (seconds), e.g. 0:2:0.04".into()));
        };
        let a = number(a)?;
        let b = if b.trim().eq_ignore_ascii_case("end") {
            animation_end
                .ok_or_else(|| bad("'end' is the end of the file's animation, and none is chosen".into()))?
        } else {
            number(b)?
        };
        let step: f64 =
            s.trim().parse().map_err(|_| bad(format!("the step '{}' is not a number", s.trim())))?;
        if !(step.is_finite() && step > 0.0) {
            return Err(bad(format!("the step {step} is not a positive number of seconds")));
        }
        if b < a {
            return Err(bad(format!("the end {b} s comes before the start {a} s")));
        }
        let steps = ((b - a) / step * (1.0 + 1e-9)).floor();
        if steps + 1.0 > MAX_FRAMES as f64 {
            return Err(bad(format!("{} frames; at most {MAX_FRAMES}", steps + 1.0)));
        }
        // Each moment from the start, not by adding steps: no drift over long sequences; to the
        // nanosecond, so that 0.1 × 3 reads 0.3 in names and messages.
        (0..=steps as usize).map(|i| ((a + i as f64 * step) * 1e9).round() / 1e9).map(|t| t.min(b)).collect()
    } else {
        let list: Vec<&str> = arg.split(',').collect();
        if list.len() > MAX_FRAMES {
            return Err(bad(format!("{} frames; at most {MAX_FRAMES}", list.len())));
        }
        list.into_iter().map(number).collect::<Result<Vec<_>>>()?
    };
    Ok(times)
}

/// Where the frame number goes in a file name: `%d` or `%0Nd` (N from 1 to 9), as ffmpeg
/// reads a sequence; (start, end, width) of the one occurrence.
fn placeholder(name: &str) -> Option<(usize, usize, usize)> {
    let b = name.as_bytes();
    let mut found = None;
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let (width, len) = match (b.get(i + 1), b.get(i + 2), b.get(i + 3)) {
                (Some(b'd'), _, _) => (0, 2),
                (Some(b'0'), Some(n @ b'1'..=b'9'), Some(b'd')) => ((n - b'0') as usize, 4),
                _ => return None,
            };
            if found.is_some() {
                return None;
            }
            found = Some((i, i + len, width));
            i += len;
        } else {
            i += 1;
        }
    }
    found
}

/// The file of frame `index` of a sequence written to `pattern` (see [`placeholder`]).
pub fn frame_path(flag: &str, pattern: &Path, index: usize) -> Result<PathBuf> {
    let name = pattern.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    let Some((start, end, width)) = placeholder(name) else {
        bail!(
            "{flag} {}: a sequence of frames needs one frame-number pattern in the file name, %d or %0Nd \
             (e.g. fox_%04d.png; a literal % is not allowed)",
            pattern.display()
        );
    };
    Ok(pattern.with_file_name(format!("{}{index:0width$}{}", &name[..start], &name[end..])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_times_(arg: &str) -> Result<Vec<f64>> {
        parse_times(arg, None)
    }

    #[test]
    fn ranges_and_lists() {
        assert_eq!(parse_times_("0:1:0.25").unwrap(), [0.0, 0.25, 0.5, 0.75, 1.0]);
        // The end is kept when a step lands on it despite rounding (0.1 × 30 is 3.0000000000000004).
        let t = parse_times_("0:3:0.1").unwrap();
        assert_eq!(t.len(), 31);
        assert_eq!(*t.last().unwrap(), 3.0);
        assert_eq!(parse_times_("0.5:1.2:0.5").unwrap(), [0.5, 1.0]);
        assert_eq!(parse_times_("0:0.3:0.1").unwrap(), [0.0, 0.1, 0.2, 0.3]);
        assert_eq!(parse_times_("2:2:1").unwrap(), [2.0]);
        assert_eq!(parse_times_("0, 0.5,1.25").unwrap(), [0.0, 0.5, 1.25]);
        assert_eq!(parse_times_("3").unwrap(), [3.0]);
        assert!(needs_end("0.5:END:0.25") && !needs_end("0:1:0.5") && !needs_end("0,1"));
        assert_eq!(start("0.5:end:0.25").unwrap(), 0.5);
        assert_eq!(parse_times("0.5:end:0.25", Some(1.1)).unwrap(), [0.5, 0.75, 1.0]);
        assert!(parse_times("2:end:0.25", Some(1.0)).unwrap_err().to_string().contains("comes before"));
        for (arg, want) in [
            ("1:0:0.1", "comes before"),
            ("0:1:0", "not a positive"),
            ("0:1:-1", "not a positive"),
            ("0:1:nan", "not a positive"),
            ("0:1", "START:END:STEP"),
            ("0:1:2:3", "START:END:STEP"),
            ("-1:1:1", "outside 0"),
            ("0:1e7:1", "outside 0"),
            ("0:100000:0.5", "200001 frames; at most 100000"),
            ("0,x", "'x' is not a number"),
            ("inf", "inf s is outside 0"),
            ("0:end:0.5", "none is chosen"),
        ] {
            let e = parse_times_(arg).unwrap_err().to_string();
            assert!(e.starts_with(&format!("--times {arg}: ")) && e.contains(want), "{arg}: {e}");
        }
    }

    #[test]
    fn frame_names() {
        let p = |s: &str, i| frame_path("--out", Path::new(s), i).map(|p| p.display().to_string());
        assert_eq!(p("out/fox_%04d.png", 7).unwrap(), "out/fox_0007.png");
        assert_eq!(p("f%d.exr", 12).unwrap(), "f12.exr");
        assert_eq!(p("f%02d.exr", 123).unwrap(), "f123.exr");
        // The pattern belongs to the file name, not a folder.
        assert!(p("out%04d/fox.png", 1).is_err());
        for bad in ["fox.png", "a%04d_%04d.png", "100%.png", "f%4d.png", "f%s.png"] {
            let e = p(bad, 0).unwrap_err().to_string();
            assert!(e.contains("frame-number pattern") && e.contains(bad), "{e}");
        }
    }
}
