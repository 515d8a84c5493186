//! Charts as SVG or PNG (plotters draws the axes and the data into an SVG document; the title
//! and the legend are laid out here; `raster.rs` renders PNG with the bundled font): time
//! histories of a run (`mbd plot`), work-precision charts, stability maps and fan plots.
//!
//! Contract: a chart is one SVG document (or its PNG) with a title, labelled axes, one line per
//! series and a legend beside the plot, never over the data; the tick labels come from
//! `ticks.rs` and are thinned until no two overlap; text is set in the bundled font
//! ([`raster::FAMILY`]) and measured with it, so nothing is clipped. Non-finite points are
//! skipped (a run that failed keeps the rows written so far, and the chart shows them); on log
//! axes non-positive values are skipped. The legend of panel `k` is the SVG group
//! `legend-k`, the title the text `title` (what the tests look for).

use super::guides::clipped;
use super::legend::{entries, legend, legend_layout, title, MARKED};
use super::raster::{self, FAMILY};
use super::ticks::{self, Ticks};
use plotters::coord::ranged1d::{AsRangedCoord, DefaultFormatting, KeyPointHint, Ranged};
use plotters::element::DashedPathElement;
use plotters::prelude::*;

/// One line of a chart.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Markers without a line (scattered values, e.g. every mode's exponent).
    pub markers_only: bool,
}

/// A faint reference line: not data, drawn under it, named in the legend.
#[derive(Clone, Debug, PartialEq)]
pub struct Guide {
    pub label: String,
    pub line: GuideLine,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GuideLine {
    /// A horizontal line at this y (a target error).
    Level(f64),
    /// `y = y0 (x / x0)^slope` through `through = (x0, y0)`: a straight line of that slope on
    /// log-log axes (an order of convergence).
    Slope { through: (f64, f64), slope: f64 },
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
    pub guides: Vec<Guide>,
}

impl Chart {
    /// A chart of `series` with no shading and no guides.
    pub fn new(title: &str, x_label: &str, y_label: &str, series: Vec<Series>) -> Chart {
        Chart {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            log_x: false,
            log_y: false,
            series,
            shaded: Vec::new(),
            guides: Vec::new(),
        }
    }
}

/// Distinct line colours (Tableau 10).
pub const PALETTE: [RGBColor; 10] = [
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

/// The shade of unstable ranges.
pub(super) const SHADE: RGBColor = RGBColor(214, 39, 40);
pub(super) const SHADE_OPACITY: f64 = 0.12;
/// Guide lines: a light grey, dashed.
pub(super) const GUIDE: RGBColor = RGBColor(150, 150, 150);

/// The canvas width; a single chart is 500 high, a stack of panels 270 per panel.
pub const WIDTH: u32 = 800;
const TITLE_HEIGHT: i32 = 36;
const SINGLE_HEIGHT: i32 = 464;
const PANEL_HEIGHT: i32 = 270;
/// Tick labels, axis titles and legend entries are set at this size (px).
pub(super) const TEXT: f64 = 12.0;
/// plotters writes a font size of `size / 1.24` into the SVG.
const PLOTTERS_TEXT: f64 = TEXT * 1.24;
const MARGIN_TOP: i32 = 10;
const MARGIN_LEFT: i32 = 8;
const MARGIN_RIGHT: i32 = 28;
const MARGIN_BOTTOM: i32 = 4;
const X_LABEL_AREA: i32 = 44;
/// Room for the rotated y-axis title beside the y tick labels.
const Y_TITLE: f64 = 24.0;
pub(super) const LEGEND_ROW: f64 = 18.0;
pub(super) const LEGEND_SWATCH: f64 = 22.0;
/// The widest legend: longer labels are cut with an ellipsis.
pub(super) const LEGEND_MAX: f64 = 280.0;

/// The range of the finite (positive, on a log axis) values, padded so that markers at the
/// extremes stay inside the plot, and widened when degenerate.
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
        let pad = (hi / lo).powf(0.04);
        return Some(ticks::widen_log(lo / pad, hi * pad));
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return Some((lo - pad, hi + pad));
    }
    let pad = 0.05 * (hi - lo);
    Some((lo - pad, hi + pad))
}

pub(super) fn kept(p: &(f64, f64), log_x: bool, log_y: bool) -> bool {
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

/// Renders charts stacked vertically in one SVG document (800 wide, 500 for one chart, 270 per
/// panel for several): panels of one figure, e.g. channels of different units over one time
/// axis. The first chart's title is the figure's.
pub fn render_stack(charts: &[Chart]) -> Result<String, String> {
    let Some(first) = charts.first() else {
        return Err("nothing to plot: no chart".to_string());
    };
    let panel_height = if charts.len() == 1 {
        SINGLE_HEIGHT
    } else {
        PANEL_HEIGHT
    };
    let height = TITLE_HEIGHT + panel_height * charts.len() as i32;
    let mut svg = String::new();
    let mut overlay = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        for (k, chart) in charts.iter().enumerate() {
            let top = TITLE_HEIGHT + k as i32 * panel_height;
            panel(&root, chart, k, (top, panel_height), &mut overlay)?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    title(&first.title, &mut overlay);
    let end = svg
        .rfind("</svg>")
        .ok_or("the SVG backend wrote no document")?;
    svg.insert_str(end, &overlay);
    Ok(svg)
}

/// The charts as PNG (the SVG of [`render_stack`] rasterised with the bundled font).
pub fn render_png(charts: &[Chart]) -> Result<Vec<u8>, String> {
    raster::png(&render_stack(charts)?)
}

/// The charts as the bytes of a file named `path`: PNG for a `.png` name, else SVG.
pub fn encode(charts: &[Chart], path: &str) -> Result<Vec<u8>, String> {
    let png = std::path::Path::new(path)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if png {
        render_png(charts)
    } else {
        render_stack(charts).map(String::into_bytes)
    }
}

/// The ticks of both axes, thinned for a plot `plot_w` wide and `height` high, and the width of
/// the y labels' area (the widest label, a gap and the rotated axis title).
fn axes(
    chart: &Chart,
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    plot_w: i32,
    height: i32,
) -> (Ticks, Ticks, i32) {
    let (lx, ly) = (chart.log_x, chart.log_y);
    let axis = |lo: f64, hi: f64, log: bool| -> Ticks {
        if log {
            ticks::log(lo, hi)
        } else {
            ticks::linear(lo, hi)
        }
    };
    let (mut xt, mut yt) = (axis(x0, x1, lx), axis(y0, y1, ly));
    let labels = |t: &Ticks| t.major.iter().map(|m| m.1.clone()).collect::<Vec<_>>();
    let y_widest = raster::widths(&labels(&yt), TEXT)
        .into_iter()
        .fold(0.0f64, f64::max);
    let y_area = (y_widest + 12.0 + Y_TITLE).ceil() as i32;
    let inner_w = (plot_w - MARGIN_LEFT - MARGIN_RIGHT - y_area) as f64;
    let inner_h = (height - MARGIN_TOP - MARGIN_BOTTOM - X_LABEL_AREA) as f64;
    let x_sizes = raster::widths(&labels(&xt), TEXT);
    ticks::thin(&mut xt, (x0, x1), lx, inner_w, &x_sizes);
    let y_sizes = vec![TEXT; yt.major.len()];
    ticks::thin(&mut yt, (y0, y1), ly, inner_h, &y_sizes);
    (xt, yt, y_area)
}

/// Draws panel `k` of a figure: its plot (plotters) on `root` at rows `top .. top + height`,
/// its legend into `overlay`.
fn panel(
    root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    chart: &Chart,
    k: usize,
    (top, height): (i32, i32),
    overlay: &mut String,
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
    let (shades, guides) = clipped(chart, (x0, x1), (y0, y1));
    let (legend_w, entries) = legend_layout(entries(chart, !shades.is_empty(), &guides));
    let plot_w = if entries.is_empty() {
        WIDTH as i32
    } else {
        WIDTH as i32 - legend_w.ceil() as i32 - 12
    };
    let (xt, yt, y_area) = axes(chart, ((x0, x1), (y0, y1)), plot_w, height);
    let room = (height - MARGIN_TOP - MARGIN_BOTTOM - X_LABEL_AREA / 2) as f64;
    let at = (plot_w as f64 + 4.0, (top + MARGIN_TOP) as f64, legend_w);
    legend(k, &entries, at, room, overlay);

    let area = root
        .clone()
        .shrink((0, top), (plot_w as u32, height as u32));
    let (x_label, y_label) = (|v: &f64| xt.label(*v), |v: &f64| yt.label(*v));
    let e = |e: DrawingAreaErrorKind<std::io::Error>| e.to_string();
    let font = (FAMILY, PLOTTERS_TEXT);
    let mut builder = ChartBuilder::on(&area);
    builder
        .margin_top(MARGIN_TOP)
        .margin_bottom(MARGIN_BOTTOM)
        .margin_left(MARGIN_LEFT)
        .margin_right(MARGIN_RIGHT)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(y_area);
    // The four axis kinds are four coordinate types; one macro draws each.
    macro_rules! draw {
        ($xr:expr, $yr:expr) => {{
            let mut c = builder.build_cartesian_2d($xr, $yr).map_err(e)?;
            c.configure_mesh()
                .x_label_formatter(&x_label)
                .y_label_formatter(&y_label)
                .x_desc(chart.x_label.as_str())
                .y_desc(chart.y_label.as_str())
                .label_style(font)
                .axis_desc_style(font)
                .draw()
                .map_err(e)?;
            let shade = SHADE.mix(SHADE_OPACITY);
            c.draw_series(
                shades
                    .iter()
                    .map(|&(a, b)| Rectangle::new([(a, y0), (b, y1)], shade.filled())),
            )
            .map_err(e)?;
            for (g, ends) in &guides {
                let (dash, gap) = match g.line {
                    GuideLine::Slope { .. } => (6, 4),
                    GuideLine::Level(_) => (2, 3),
                };
                c.draw_series(std::iter::once(DashedPathElement::new(
                    ends.clone(),
                    dash,
                    gap,
                    GUIDE.stroke_width(1),
                )))
                .map_err(e)?;
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
                        .map_err(e)?;
                    continue;
                }
                c.draw_series(LineSeries::new(
                    points.iter().copied(),
                    colour.stroke_width(2),
                ))
                .map_err(e)?;
                if points.len() <= MARKED {
                    c.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                        .map_err(e)?;
                }
            }
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
    Ok(())
}

/// What a channel measures and its unit, for its axis: (`joint angle`, `rad`).
pub type Quantity = (String, String);

/// Time histories of the named channels of a run's CSV (header `t`, then channels): one panel
/// per unit, `describe(channel)` giving its quantity and unit; the y axis names the quantity
/// the panel's channels share (`joint angle [rad]`) or the channels (`zeta1, x_hub [m]`).
/// Channels the model does not describe share one panel said to be in SI units.
pub fn time_history(
    title: &str,
    header: &[String],
    rows: &[Vec<f64>],
    channels: &[String],
    describe: &dyn Fn(&str) -> Option<Quantity>,
) -> Result<Vec<Chart>, String> {
    let t = header
        .iter()
        .position(|h| h == "t")
        .ok_or("the CSV has no `t` column")?;
    // Panels in the order their first channel was asked for.
    type Panel = (Option<String>, Vec<(Series, Option<String>)>);
    let mut panels: Vec<Panel> = Vec::new();
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
        let (quantity, unit) = match describe(name) {
            Some((q, u)) => (Some(q), Some(u)),
            None => (None, None),
        };
        match panels.iter_mut().find(|(pu, _)| *pu == unit) {
            Some((_, list)) => list.push((series, quantity)),
            None => panels.push((unit, vec![(series, quantity)])),
        }
    }
    Ok(panels
        .into_iter()
        .map(|(unit, list)| {
            let names: Vec<&str> = list.iter().map(|(s, _)| s.label.as_str()).collect();
            let first = list.first().and_then(|(_, q)| q.clone());
            let shared = first.filter(|q| list.iter().all(|(_, x)| x.as_ref() == Some(q)));
            let y_label = match (&unit, shared, names.len()) {
                (Some(u), Some(q), 1) => format!("{}: {q} [{u}]", names[0]),
                (Some(u), Some(q), _) => format!("{q} [{u}]"),
                (Some(u), None, n) if n <= 3 => format!("{} [{u}]", names.join(", ")),
                (Some(u), None, _) => format!("values [{u}]"),
                (None, _, n) if n <= 3 => format!("{} (SI units)", names.join(", ")),
                (None, _, _) => "values (SI units)".to_string(),
            };
            Chart::new(
                title,
                "t [s]",
                &y_label,
                list.into_iter().map(|(s, _)| s).collect(),
            )
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
            guides: Vec::new(),
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
            "0.006", "0.007", "0.008", "0.009", "0.01", "1e-6", "1e-5", "1e-4", "1e-3",
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
