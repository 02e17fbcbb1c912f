//! `riverplanet plot`: the figures of Chapter 9 from the JSON of `bench flight`, as SVG and PNG (plotters; text
//! in DejaVu Sans from the system, which tools/setup installs).

use std::path::Path;

use plotters::prelude::*;
use serde_json::Value;

/// Why a plot was not drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A report cannot be read.
    #[error("cannot read {path}: {message}")]
    Read {
        /// The report.
        path: String,
        /// The operating system's or the JSON parser's reason.
        message: String,
    },
    /// A report is not the kind the plot needs.
    #[error("{path} is not a `{expected}` report: {message}")]
    Format {
        /// The report.
        path: String,
        /// The command whose report it must be.
        expected: &'static str,
        /// What is missing or wrong.
        message: String,
    },
    /// The figure cannot be drawn or written.
    #[error("cannot draw {path}: {message}")]
    Draw {
        /// The figure's file.
        path: String,
        /// plotters' reason.
        message: String,
    },
    /// The font is missing.
    #[error("no font for the plots: {0} (install fonts-dejavu-core)")]
    Font(String),
}

const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

fn register_font() -> Result<(), PlotError> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        let bytes = std::fs::read(FONT).map_err(|e| format!("{FONT}: {e}"))?;
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| format!("{FONT}: invalid"))
    })
    .clone()
    .map_err(PlotError::Font)
}

/// One line of a chart.
pub struct Series {
    /// The legend's name.
    pub name: String,
    /// (x, y) in drawing order.
    pub points: Vec<(f64, f64)>,
}

/// The frames before this are the flight's start (patches of every level arriving at once): their spikes are left
/// off a chart's scale when they would flatten the rest, and the title says how high they reach.
const START_FRAMES: f64 = crate::bench::flight::WARMUP_FRAMES as f64;

/// The runs of consecutive frames of `points`: a line is drawn along each, none across frames without data; a run
/// of one frame is a short tick.
fn runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    for &p in points {
        match runs.last_mut() {
            Some(run) if run.last().is_some_and(|q| p.0 - q.0 <= 1.0) => run.push(p),
            _ => runs.push(vec![p]),
        }
    }
    for run in &mut runs {
        if let [(x, y)] = run[..] {
            *run = vec![(x - 0.4, y), (x + 0.4, y)];
        }
    }
    runs
}

/// A line chart over the `frames` frames of a flight, written to `base.svg` and `base.png`: integer frames, no
/// line across frames without data, the start's spikes off the scale where they would flatten the rest, and the
/// camera's `altitude` per frame on a second axis (grey).
pub fn line_chart(
    base: &Path,
    title: &str,
    y_label: &str,
    series: &[Series],
    (frames, altitude): (usize, &[f64]),
) -> Result<(), PlotError> {
    register_font()?;
    let draw_err = |e: &dyn std::fmt::Display| PlotError::Draw {
        path: base.display().to_string(),
        message: e.to_string(),
    };
    let x_max = (frames.max(2) - 1) as f64;
    let highest = |after: f64| {
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(move |p| p.0 >= after).map(|p| p.1))
            .fold(0.0, f64::max)
    };
    let (all, later) = (highest(0.0), highest(START_FRAMES));
    let (y_max, title) = if later > 0.0 && all > 1.5 * later {
        (
            later * 1.12,
            format!(
                "{title} (frames 0-{} reach {all:.1}, off the scale)",
                START_FRAMES - 1.0
            ),
        )
    } else {
        (all.max(1e-6) * 1.08, title.to_string())
    };
    let altitude_max = altitude.iter().copied().fold(1e-6, f64::max) * 1.05;
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
        RGBColor(214, 39, 40),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
    ];
    let grey = RGBColor(150, 150, 150);
    let (w, h) = (960u32, 540u32);
    macro_rules! draw {
        ($backend:expr) => {{
            let root = $backend.into_drawing_area();
            root.fill(&WHITE).map_err(|e| draw_err(&e))?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&title, ("sans-serif", 22))
                .margin(16)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .right_y_label_area_size(70)
                .build_cartesian_2d(0.0..x_max, 0.0..y_max)
                .map_err(|e| draw_err(&e))?
                .set_secondary_coord(0.0..x_max, 0.0..altitude_max);
            chart
                .configure_mesh()
                .x_desc("frame")
                .y_desc(y_label)
                .x_label_formatter(&|x| format!("{x:.0}"))
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| draw_err(&e))?;
            chart
                .configure_secondary_axes()
                .y_desc("altitude (world units)")
                .y_label_formatter(&|a| format!("{a:.0}"))
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(|e| draw_err(&e))?;
            chart
                .draw_secondary_series(LineSeries::new(
                    altitude.iter().enumerate().map(|(k, a)| (k as f64, *a)),
                    grey.stroke_width(1),
                ))
                .map_err(|e| draw_err(&e))?
                .label("altitude (right axis)")
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], grey.stroke_width(1))
                });
            for (k, s) in series.iter().enumerate() {
                let colour = colours[k % colours.len()];
                chart
                    .draw_series(
                        runs(&s.points)
                            .into_iter()
                            .map(|run| PathElement::new(run, colour.stroke_width(2))),
                    )
                    .map_err(|e| draw_err(&e))?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(|e| draw_err(&e))?;
            root.present().map_err(|e| draw_err(&e))?;
        }};
    }
    let svg = base.with_extension("svg");
    draw!(SVGBackend::new(&svg, (w, h)));
    let mut pixels = vec![0u8; (w * h * 3) as usize];
    draw!(BitMapBackend::with_buffer(&mut pixels, (w, h)));
    let image = image::RgbImage::from_raw(w, h, pixels).ok_or_else(|| draw_err(&"buffer size"))?;
    crate::export::files::save_image(&image, &base.with_extension("png")).map_err(|e| draw_err(&e))
}

/// The JSON report at `path`, which must be one of `command`'s: it has the top-level `key` (a report of another
/// command would otherwise give empty figures or NaN tables).
pub(super) fn read_report(
    path: &Path,
    command: &'static str,
    key: &str,
) -> Result<Value, PlotError> {
    let format = |message: String| PlotError::Format {
        path: path.display().to_string(),
        expected: command,
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| PlotError::Read {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let value: Value = serde_json::from_str(&text).map_err(|e| format(e.to_string()))?;
    if value.get(key).is_none() {
        return Err(format(format!("it has no `{key}`")));
    }
    Ok(value)
}

fn series(frames: &[Value], name: &str, f: impl Fn(&Value) -> Option<f64>) -> Series {
    Series {
        name: name.to_string(),
        points: frames
            .iter()
            .enumerate()
            .filter_map(|(k, v)| f(v).map(|y| (k as f64, y)))
            .collect(),
    }
}

/// Writes the figures of one flight report into `out` with file names starting with `prefix`: returns the base
/// names written.
pub fn flight_figures(
    report: &Path,
    out: &Path,
    prefix: &str,
    stress: bool,
) -> Result<Vec<String>, PlotError> {
    let value = read_report(report, "bench flight", "frames")?;
    let frames = value["frames"].as_array().cloned().unwrap_or_default();
    std::fs::create_dir_all(out).map_err(|e| PlotError::Draw {
        path: out.display().to_string(),
        message: e.to_string(),
    })?;
    let k = |key: &'static str| move |v: &Value| v["kernels"][key].as_f64();
    let g = |key: &'static str| move |v: &Value| Some(v["gpu_ms"][key].as_f64().unwrap_or(0.0));
    let num = |key: &'static str| move |v: &Value| v[key].as_f64();
    let mb = |key: &'static str| move |v: &Value| v[key].as_f64().map(|b| b / 1e6);
    let (f1, f2, f3, f4) = if stress {
        ("9_6", "9_5", "9_7", "9_8")
    } else {
        ("9_1", "9_2", "9_3", "9_4")
    };
    let label = if stress { " (stress test)" } else { "" };
    let mut written = Vec::new();
    let altitude: Vec<f64> = frames
        .iter()
        .map(|f| f["altitude"].as_f64().unwrap_or(f64::NAN))
        .collect();
    let mut chart =
        |name: String, title: String, y: &str, s: Vec<Series>| -> Result<(), PlotError> {
            line_chart(&out.join(&name), &title, y, &s, (frames.len(), &altitude))?;
            written.push(name);
            Ok(())
        };
    chart(
        format!("{prefix}fig{f1}_cpu_vs_gpu"),
        format!("Kernel time per frame: CPU vs GPU{label}"),
        "ms",
        vec![
            series(&frames, "CPU single thread", k("cpu_single_ms")),
            series(&frames, "CPU rayon", k("cpu_rayon_ms")),
            series(&frames, "GPU tiled (kernel)", k("gpu_tiled_ms")),
            series(
                &frames,
                "GPU tiled (end to end)",
                k("gpu_tiled_end_to_end_ms"),
            ),
        ],
    )?;
    chart(
        format!("{prefix}fig{f2}a_patches"),
        format!("Patches per frame{label}"),
        "patches",
        vec![
            series(&frames, "new patches", num("new_patches")),
            series(&frames, "new river patches", num("river_patches")),
            series(&frames, "visible patches", num("visible_patches")),
        ],
    )?;
    chart(
        format!("{prefix}fig{f2}b_samples"),
        format!("Samples per frame / 100{label}"),
        "samples / 100",
        vec![series(&frames, "samples / 100", |v| {
            v["samples"].as_f64().map(|s| s / 100.0)
        })],
    )?;
    chart(
        format!("{prefix}fig{f3}_simple_vs_tiled"),
        format!("GPU kernel time: simple vs tiled (kernel only){label}"),
        "ms",
        vec![
            series(&frames, "simple", k("gpu_simple_ms")),
            series(&frames, "tiled", k("gpu_tiled_ms")),
        ],
    )?;
    chart(
        format!("{prefix}fig{f4}_memory"),
        format!(
            "Memory per frame{label} (plus {:.1} MB of precomputed heights)",
            frames
                .first()
                .and_then(|f| f["precomputed_height_bytes"].as_f64())
                .unwrap_or(0.0)
                / 1e6
        ),
        "MB",
        vec![
            series(&frames, "patch textures", mb("patch_texture_bytes")),
            series(
                &frames,
                "temporary sample data",
                mb("temporary_sample_bytes"),
            ),
        ],
    )?;
    let mut water = vec![series(&frames, "auto", num("frame_ms"))];
    if let Some(modes) = value["water_mode_frames"].as_object() {
        for (mode, times) in modes {
            let times = times.as_array().cloned().unwrap_or_default();
            water.push(Series {
                name: mode.clone(),
                points: times
                    .iter()
                    .enumerate()
                    .filter_map(|(k, t)| t.as_f64().map(|t| (k as f64, t)))
                    .collect(),
            });
        }
    }
    chart(
        format!("{prefix}frame_time_by_water_mode"),
        format!("Frame time per water mode{label}"),
        "ms",
        water,
    )?;
    chart(
        format!("{prefix}gpu_passes"),
        format!("GPU time per pass{label}"),
        "ms",
        vec![
            series(&frames, "kernel", g("kernel")),
            series(&frames, "vertex cache", g("vertices")),
            series(&frames, "terrain", g("terrain")),
            series(&frames, "water", g("water")),
            series(&frames, "sky", g("sky")),
        ],
    )?;
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::runs;

    #[test]
    fn lines_run_along_consecutive_frames_only_and_a_lone_frame_is_a_tick() {
        let points = [(0.0, 1.0), (1.0, 2.0), (5.0, 3.0), (7.0, 4.0), (8.0, 5.0)];
        let r = runs(&points);
        assert_eq!(r.len(), 3);
        assert_eq!(r[0], vec![(0.0, 1.0), (1.0, 2.0)]);
        assert_eq!(r[1], vec![(4.6, 3.0), (5.4, 3.0)]);
        assert_eq!(r[2], vec![(7.0, 4.0), (8.0, 5.0)]);
    }
}
