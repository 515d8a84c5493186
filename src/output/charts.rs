//! SVG charts (plotters, SVG backend only: no fonts or native libraries): time histories of a
//! run (`mbd plot`), and log-log charts of error against cost.
//!
//! Contract: a chart is one SVG document with a title, labelled axes, one line per series and a
//! legend; non-finite points are skipped (a run that failed keeps the rows written so far, and
//! the chart shows them); on log axes non-positive values are skipped.

use super::ticks::{self, Ticks};
use plotters::coord::ranged1d::{AsRangedCoord, DefaultFormatting, KeyPointHint, Ranged};
use plotters::prelude::*;

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Markers without a line (scattered values, e.g. every mode's exponent).
    pub markers_only: bool,
}

/// What to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub series: Vec<Series>,
    /// Ranges of x shaded in light red (unstable ranges of a stability chart).
    pub shaded: Vec<(f64, f64)>,
}

/// Distinct line colours (Tableau 10).
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The range of the finite (positive, on a log axis) values, widened when degenerate.
fn range(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values {
        if v.is_finite() && (!log || v > 0.0) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo > hi {
        return None;
    }
    if log {
        if hi <= lo * (1.0 + 1e-12) {
            return Some((lo / 2.0, hi * 2.0));
        }
        return Some((lo, hi));
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return Some((lo - pad, hi + pad));
    }
    let pad = 0.05 * (hi - lo);
    Some((lo - pad, hi + pad))
}

fn kept(p: &(f64, f64), log_x: bool, log_y: bool) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!log_x || p.0 > 0.0) && (!log_y || p.1 > 0.0)
}

/// An axis (linear or log) with the ticks of `ticks.rs`: its labelled positions as the bold
/// key points, its minor ones as the light key points. (plotters' own `WithKeyPoints` loses the
/// value formatter of `f64` axes, which `configure_mesh` needs.)
struct Keyed<R: Ranged<ValueType = f64>> {
    inner: R,
    major: Vec<f64>,
    minor: Vec<f64>,
}

fn keyed<A: AsRangedCoord<Value = f64>>(range: A, ticks: &Ticks) -> Keyed<A::CoordDescType> {
    Keyed {
        inner: range.into(),
        major: ticks.positions(),
        minor: ticks.minor.clone(),
    }
}

impl<R: Ranged<ValueType = f64>> Ranged for Keyed<R> {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.major.clone()
        }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> std::ops::Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

/// Renders a chart as an SVG document (800 x 500).
pub fn render(chart: &Chart) -> Result<String, String> {
    render_stack(std::slice::from_ref(chart))
}

/// Renders charts stacked vertically in one SVG document (800 wide, 500 for one chart, 300 per
/// chart for several): panels of one figure, e.g. channels of different units over one time
/// axis. The first chart's title is the figure's.
pub fn render_stack(charts: &[Chart]) -> Result<String, String> {
    if charts.is_empty() {
        return Err("nothing to plot: no chart".to_string());
    }
    let height = if charts.len() == 1 {
        500
    } else {
        60 + 280 * charts.len() as u32
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (800, height)).into_drawing_area();
        let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
        root.fill(&WHITE).map_err(e)?;
        let areas = root.split_evenly((charts.len(), 1));
        for (k, (chart, area)) in charts.iter().zip(&areas).enumerate() {
            draw(area, chart, k == 0)?;
        }
        root.present().map_err(e)?;
    }
    Ok(svg)
}

/// Draws one chart on an area, with its title if `caption`.
fn draw(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    chart: &Chart,
    caption: bool,
) -> Result<(), String> {
    let (lx, ly) = (chart.log_x, chart.log_y);
    let pts = || {
        chart
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(move |p| kept(p, lx, ly))
    };
    let (x0, x1) = range(pts().map(|p| p.0), lx).ok_or("nothing to plot: no finite points")?;
    let (y0, y1) = range(pts().map(|p| p.1), ly).ok_or("nothing to plot: no finite points")?;
    let axis = |lo: f64, hi: f64, log: bool| -> Ticks {
        if log {
            ticks::log(lo, hi)
        } else {
            ticks::linear(lo, hi)
        }
    };
    let (xt, yt) = (axis(x0, x1, lx), axis(y0, y1, ly));
    let (x_label, y_label) = (|v: &f64| xt.label(*v), |v: &f64| yt.label(*v));
    {
        let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
        let mut builder = ChartBuilder::on(root);
        if caption {
            builder.caption(&chart.title, ("sans-serif", 20));
        }
        builder
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(72);
        // The four axis kinds are four coordinate types; one macro draws each.
        macro_rules! draw {
            ($xr:expr, $yr:expr) => {{
                let mut c = builder.build_cartesian_2d($xr, $yr).map_err(e)?;
                c.configure_mesh()
                    .x_label_formatter(&x_label)
                    .y_label_formatter(&y_label)
                    .x_desc(chart.x_label.as_str())
                    .y_desc(chart.y_label.as_str())
                    .draw()
                    .map_err(e)?;
                let shade = RGBColor(214, 39, 40).mix(0.12);
                for (k, &(a, b)) in chart.shaded.iter().enumerate() {
                    let (a, b) = (a.max(x0), b.min(x1));
                    if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
                        continue;
                    }
                    let area = c
                        .draw_series(std::iter::once(Rectangle::new(
                            [(a, y0), (b, y1)],
                            shade.filled(),
                        )))
                        .map_err(e)?;
                    if k == 0 {
                        area.label("unstable").legend(move |(x, y)| {
                            Rectangle::new([(x, y - 5), (x + 20, y + 5)], shade.filled())
                        });
                    }
                }
                for (k, s) in chart.series.iter().enumerate() {
                    let colour = PALETTE[k % PALETTE.len()];
                    let points: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|p| kept(p, lx, ly))
                        .collect();
                    if s.markers_only {
                        c.draw_series(points.iter().map(|&p| Circle::new(p, 2, colour.filled())))
                            .map_err(e)?
                            .label(s.label.as_str())
                            .legend(move |(x, y)| Circle::new((x + 10, y), 3, colour.filled()));
                        continue;
                    }
                    let style = colour.stroke_width(2);
                    c.draw_series(LineSeries::new(points.iter().copied(), style))
                        .map_err(e)?
                        .label(s.label.as_str())
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                        });
                    // Markers where a series has few points (study charts).
                    if points.len() <= 40 {
                        c.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                            .map_err(e)?;
                    }
                }
                c.configure_series_labels()
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(e)?;
            }};
        }
        match (lx, ly) {
            (false, false) => draw!(keyed(x0..x1, &xt), keyed(y0..y1, &yt)),
            (true, false) => draw!(keyed((x0..x1).log_scale(), &xt), keyed(y0..y1, &yt)),
            (false, true) => draw!(keyed(x0..x1, &xt), keyed((y0..y1).log_scale(), &yt)),
            (true, true) => draw!(
                keyed((x0..x1).log_scale(), &xt),
                keyed((y0..y1).log_scale(), &yt)
            ),
        }
    }
    Ok(())
}

/// Time histories of the named channels of a run's CSV (header `t`, then channels): one panel
/// per unit, `unit(channel)` giving it (`m`, `rad`, `N`); channels without a known unit share
/// one panel labelled in SI.
pub fn time_history(
    title: &str,
    header: &[String],
    rows: &[Vec<f64>],
    channels: &[String],
    unit: &dyn Fn(&str) -> Option<String>,
) -> Result<Vec<Chart>, String> {
    let t = header
        .iter()
        .position(|h| h == "t")
        .ok_or("the CSV has no `t` column")?;
    // Panels in the order their first channel was asked for.
    let mut panels: Vec<(Option<String>, Vec<Series>)> = Vec::new();
    for name in channels {
        let Some(k) = header.iter().position(|h| h == name) else {
            let known: Vec<&str> = header
                .iter()
                .filter(|h| h.as_str() != "t")
                .map(String::as_str)
                .collect();
            return Err(format!(
                "no channel `{name}` in the CSV; its channels are: {}",
                known.join(", ")
            ));
        };
        let series = Series {
            label: name.clone(),
            points: rows.iter().map(|r| (r[t], r[k])).collect(),
            markers_only: false,
        };
        let u = unit(name);
        match panels.iter_mut().find(|(pu, _)| *pu == u) {
            Some((_, list)) => list.push(series),
            None => panels.push((u, vec![series])),
        }
    }
    Ok(panels
        .into_iter()
        .map(|(u, series)| {
            let names: Vec<&str> = series.iter().map(|s| s.label.as_str()).collect();
            let y_label = match (&u, names.len()) {
                (Some(u), n) if n <= 3 => format!("{} [{u}]", names.join(", ")),
                (Some(u), _) => format!("[{u}]"),
                (None, 1) => names[0].to_string(),
                (None, _) => "value (SI)".to_string(),
            };
            Chart {
                title: title.to_string(),
                x_label: "t [s]".to_string(),
                y_label,
                log_x: false,
                log_y: false,
                series,
                shaded: Vec::new(),
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(points: Vec<(f64, f64)>, log: bool) -> Chart {
        Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            log_x: log,
            log_y: log,
            series: vec![Series {
                label: "s".into(),
                points,
                markers_only: false,
            }],
            shaded: Vec::new(),
        }
    }

    #[test]
    fn renders_lines_and_skips_non_finite_points() {
        let svg = render(&chart(vec![(0.0, 1.0), (1.0, f64::NAN), (2.0, 3.0)], false));
        let svg = svg.unwrap_or_default();
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("<polyline"));
    }

    /// The texts of an SVG document.
    fn texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| {
                let body = t.split_once('>')?.1;
                Some(body.split_once("</text>")?.0.trim().to_string())
            })
            .collect()
    }

    /// Issue 19: the P3 chart's x axis (0.006 .. 0.01) showed one tick or piled-up labels, and
    /// log labels float artefacts; linear axes wrote `-0.0`.
    #[test]
    fn axes_are_labelled_with_the_ticks_and_no_float_artefacts() {
        let svg = render(&chart(
            vec![(0.006, 2e-7), (0.0085, 3e-5), (0.01, 4e-3)],
            true,
        ))
        .unwrap_or_default();
        let t = texts(&svg);
        for label in [
            "0.006", "0.007", "0.008", "0.009", "0.01", "1e-6", "1e-5", "0.0001", "0.001",
        ] {
            assert!(t.iter().any(|x| x == label), "{label} missing from {t:?}");
        }
        let svg = render(&chart(vec![(0.0, -0.31), (1.0, 0.72)], false)).unwrap_or_default();
        let t = texts(&svg);
        assert!(
            t.iter().any(|x| x == "0") && t.iter().any(|x| x == "-0.2"),
            "{t:?}"
        );
        for x in &t {
            assert!(!x.starts_with("-0") || x.starts_with("-0."), "{x}");
            assert!(!x.contains("0000") && !x.contains("9999"), "artefact {x}");
        }
    }

    #[test]
    fn log_axes_skip_non_positive_values_and_empty_charts_are_errors() {
        assert!(render(&chart(vec![(1.0, 1e-3), (10.0, 1e-6), (0.0, 1.0)], true)).is_ok());
        assert!(render(&chart(vec![(0.0, 0.0)], true)).is_err());
        assert!(render(&chart(vec![(1.0, 2.0)], false)).is_ok());
    }
}
