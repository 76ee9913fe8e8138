//! `hooke`: runs scenario files headless and says what held.
//!
//! ```text
//! hooke run [--csv DIR] [--plot DIR] [--quiet] [--pin] FILE...
//!                                                        run, one line per expectation
//! hooke check FILE...                                    read and check the files only
//! ```
//!
//! Exit status: 0 when every expectation of every file held, 1 when one failed, 2 when a
//! file could not be read or the command line is wrong. `--csv DIR` writes one CSV trace
//! per traced entity (every named one when the file names none), `--plot DIR` a PNG of
//! their height and speed against time, `--pin` writes each file's final-state hash into
//! its `hash:` field (after a deliberate change of results). Build it with the `cli` feature:
//! `cargo run --release --features cli --bin hooke -- run scenarios/*.ron`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use hooke::tools::plot::{axes, legend, register_fonts};
use hooke::tools::scenario::{Report, RunOptions, Scenario};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::prelude::*;

const USAGE: &str =
    "usage: hooke run [--csv DIR] [--plot DIR] [--quiet] FILE...\n       hooke check FILE...";

struct Args {
    command: String,
    files: Vec<PathBuf>,
    csv: Option<PathBuf>,
    plot: Option<PathBuf>,
    quiet: bool,
    pin: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut it = std::env::args().skip(1);
    let command = it.next().ok_or(USAGE)?;
    if command != "run" && command != "check" {
        return Err(format!("unknown command \"{command}\"\n{USAGE}"));
    }
    let mut args = Args {
        command,
        files: Vec::new(),
        csv: None,
        plot: None,
        quiet: false,
        pin: false,
    };
    while let Some(a) = it.next() {
        match a.as_str() {
            "--csv" => args.csv = Some(it.next().ok_or("--csv needs a folder")?.into()),
            "--plot" => args.plot = Some(it.next().ok_or("--plot needs a folder")?.into()),
            "--quiet" => args.quiet = true,
            "--pin" => args.pin = true,
            "-h" | "--help" => return Err(USAGE.into()),
            s if s.starts_with("--") => return Err(format!("unknown option {s}\n{USAGE}")),
            _ => args.files.push(a.into()),
        }
    }
    if args.files.is_empty() {
        return Err(format!("no scenario files given\n{USAGE}"));
    }
    Ok(args)
}

fn main() -> ExitCode {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let mut scenarios = Vec::new();
    let mut unreadable = 0;
    for f in &args.files {
        match Scenario::from_file(f) {
            Ok(s) => scenarios.push((f.clone(), s)),
            Err(e) => {
                eprintln!("error: {e}");
                unreadable += 1;
            }
        }
    }
    if args.command == "check" {
        say(format_args!(
            "{} read, {unreadable} unreadable",
            scenarios.len()
        ));
        return if unreadable == 0 {
            ExitCode::SUCCESS
        } else {
            ExitCode::from(2)
        };
    }
    let total: u64 = scenarios.iter().map(|(_, s)| s.steps() + 1).sum();
    let bar = ProgressBar::new(total).with_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps, {elapsed} ({eta} left) {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let (mut passed, mut failed) = (0, 0);
    for (path, s) in &scenarios {
        bar.set_message(s.name().to_owned());
        let done = bar.position();
        let mut progress = |step: u64, _: u64| bar.set_position(done + step + 1);
        let mut options = RunOptions {
            trace_all: args.csv.is_some() || args.plot.is_some(),
            progress: Some(&mut progress),
        };
        let report = match s.run_with(&mut options) {
            Ok(r) => r,
            Err(e) => {
                bar.suspend(|| eprintln!("error: {e}"));
                unreadable += 1;
                continue;
            }
        };
        bar.suspend(|| {
            if args.quiet {
                let first = report
                    .first_failure()
                    .map(ToString::to_string)
                    .unwrap_or_default();
                say(format_args!(
                    "{} {}  hash {}  {first}",
                    if report.passed() { "PASS" } else { "FAIL" },
                    report.file,
                    report.hash_hex()
                ));
            } else {
                say(format_args!("{report}"));
            }
        });
        if report.passed() {
            passed += 1;
        } else {
            failed += 1;
        }
        if let Err(e) = write_outputs(&args, path, &report) {
            bar.suspend(|| eprintln!("error: {}: {e}", path.display()));
            unreadable += 1;
        }
    }
    bar.finish_and_clear();
    say(format_args!("scenarios: {passed} passed, {failed} failed"));
    if unreadable > 0 {
        ExitCode::from(2)
    } else if failed > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// A line on stdout; a closed pipe (`| head`) is not worth a panic.
fn say(line: std::fmt::Arguments) {
    let _ = writeln!(std::io::stdout(), "{line}");
}

fn stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "scenario".into(), |s| s.to_string_lossy().into_owned())
}

fn write_outputs(
    args: &Args,
    path: &Path,
    report: &Report,
) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(dir) = &args.csv {
        std::fs::create_dir_all(dir)?;
        for t in &report.traces {
            let name: String = t
                .name
                .chars()
                .map(|c| if c.is_alphanumeric() { c } else { '_' })
                .collect();
            t.write_csv(dir.join(format!("{}_{name}.csv", stem(path))))?;
        }
    }
    if args.pin {
        pin(path, report)?;
    }
    if let Some(dir) = &args.plot {
        std::fs::create_dir_all(dir)?;
        plot(report, &dir.join(format!("{}.png", stem(path))))?;
    }
    Ok(())
}

/// Writes the report's hash into the file's `hash:` line, or adds one before the closing
/// parenthesis.
fn pin(path: &Path, report: &Report) -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let line = format!("    hash: \"{}\",", report.hash_hex());
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    if let Some(l) = lines
        .iter_mut()
        .find(|l| l.trim_start().starts_with("hash:"))
    {
        *l = line;
    } else if let Some(end) = lines.iter().rposition(|l| l.trim() == ")") {
        lines.insert(end, line);
    } else {
        return Err("no closing parenthesis to put the hash before".into());
    }
    std::fs::write(path, lines.join("\n") + "\n")?;
    Ok(())
}

/// Height and speed of each traced entity against time, one panel each.
fn plot(report: &Report, out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    // A second registration (several files in one run) is harmless.
    register_fonts()?;
    let root = BitMapBackend::new(out, (1000, 760)).into_drawing_area();
    root.fill(&WHITE)?;
    let verdict = if report.passed() {
        "all expectations held"
    } else {
        "an expectation FAILED"
    };
    let root = root.titled(&format!("{}: {verdict}", report.name), ("sans-serif", 22))?;
    let (upper, lower) = root.split_vertically(370);
    let t_end = report.seconds.max(1e-3);
    let colors = [
        RGBColor(40, 110, 200),
        RGBColor(220, 90, 40),
        RGBColor(60, 160, 80),
        RGBColor(150, 70, 180),
        RGBColor(200, 160, 20),
        RGBColor(30, 170, 170),
        RGBColor(120, 120, 120),
        RGBColor(200, 60, 120),
    ];
    for (area, column, caption, unit) in [
        (&upper, 2usize, "height y of each traced entity", "y (m)"),
        (&lower, 7usize, "speed of each traced entity", "|v| (m/s)"),
    ] {
        let values = report
            .traces
            .iter()
            .flat_map(|t| t.rows.iter().map(move |r| r[column]));
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            if v.is_finite() {
                (a.min(v), b.max(v))
            } else {
                (a, b)
            }
        });
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        let pad = ((hi - lo) * 0.08).max(1e-3);
        let mut chart = ChartBuilder::on(area)
            .caption(caption, ("sans-serif", 15))
            .margin(12)
            .x_label_area_size(34)
            .y_label_area_size(58)
            .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))?;
        axes(&mut chart, "t (s)", unit)?;
        for (i, t) in report.traces.iter().enumerate() {
            let color = colors[i % colors.len()];
            chart
                .draw_series(LineSeries::new(
                    t.rows
                        .iter()
                        .filter(|r| r[column].is_finite())
                        .map(|r| (r[0], r[column])),
                    color.stroke_width(2),
                ))?
                .label(t.name.clone())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 18, y)], color.stroke_width(2))
                });
        }
        if !report.traces.is_empty() {
            legend(&mut chart)?;
        }
    }
    root.present()?;
    Ok(())
}
