//! What the picture-writing examples share: the bundled font (so titles and labels render
//! on a machine without system fonts) and a time colour ramp. Pictures are drawn with
//! `plotters` and encoded by its `image` (PNG) and `gif` backends.
#![allow(dead_code)]

use plotters::style::RGBColor;

/// The library's chart helpers (`hooke::tools::plot`, feature `plot`), compiled here from the
/// same source so the examples need no feature.
#[path = "../../src/tools/plot.rs"]
pub mod plot;

#[allow(unused_imports)] // each example uses some
pub use plot::{axes, legend, register_fonts};

/// A colour ramp from blue (0) to orange (1).
pub fn ramp(t: f32) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let lerp = |a: f32, b: f32| (a + (b - a) * t) as u8;
    RGBColor(lerp(40.0, 240.0), lerp(90.0, 140.0), lerp(220.0, 30.0))
}

/// The options of an animation that takes only its length and where to write it.
pub struct Clip {
    /// Simulated seconds.
    pub seconds: f32,
    /// The GIF's path (the last frame goes beside it as a PNG).
    pub out: std::path::PathBuf,
}

/// Reads `--seconds S` and `--out PATH` from the command line, defaulting to `seconds` and
/// `out`.
pub fn clip_options(seconds: f32, out: &str) -> Result<Clip, String> {
    let mut o = Clip {
        seconds,
        out: std::path::PathBuf::from(out),
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let value = it.next().ok_or(format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--seconds" => o.seconds = value.parse().map_err(|e| format!("--seconds: {e}"))?,
            "--out" => o.out = std::path::PathBuf::from(value),
            other => return Err(format!("unknown flag {other}")),
        }
    }
    Ok(o)
}
