//! Issue 19: charts read back as a reader sees them. Every chart kind is rendered (here, or
//! by the command tests, which pass their SVGs to [`check`]), parsed with the bundled font,
//! and checked: tick labels are numbers in order with at most 3 significant digits, no text
//! overlaps another text or the data, nothing is clipped, the legend stays off the data; and
//! the PNG of each deterministic kind matches a stored reference image
//! (`tests/charts/NAME.png`; `MBD_BLESS_CHARTS=1` rewrites them, to be reviewed in the diff).

use crate::common::{repo, within};
use mbd::output::charts::{self, Chart, PALETTE};
use mbd::study::convergence::{Convergence, Row};
use mbd::study::stability::{self, StabilityRow};
use resvg::tiny_skia::{Pixmap, Point, Rect};
use resvg::usvg;

/// A text as drawn: its string and its box in canvas pixels.
#[derive(Debug)]
struct Text {
    text: String,
    rect: Rect,
    legend: bool,
}

/// What a chart drew, in canvas pixels.
#[derive(Default)]
struct Drawn {
    texts: Vec<Text>,
    /// The data's line segments (polylines in a palette colour).
    segments: Vec<(Point, Point)>,
    /// The data's markers and shaded ranges.
    marks: Vec<Rect>,
    legends: Vec<Rect>,
    size: (f32, f32),
}

fn palette(paint: &usvg::Paint) -> bool {
    match paint {
        usvg::Paint::Color(c) => PALETTE
            .iter()
            .any(|p| (p.0, p.1, p.2) == (c.red, c.green, c.blue)),
        _ => false,
    }
}

fn walk(g: &usvg::Group, legend: bool, out: &mut Drawn) {
    for node in g.children() {
        match node {
            usvg::Node::Group(c) => {
                let inside = legend || c.id().starts_with("legend-");
                if c.id().starts_with("legend-") {
                    if let Some(r) = c.abs_bounding_box().to_non_zero_rect() {
                        out.legends.push(r.to_rect());
                    }
                }
                walk(c, inside, out);
            }
            usvg::Node::Text(t) => out.texts.push(Text {
                text: t.chunks().iter().map(|c| c.text()).collect(),
                rect: t.abs_bounding_box(),
                legend,
            }),
            usvg::Node::Path(p) if !legend => {
                let stroked = p.stroke().is_some_and(|s| palette(s.paint()));
                let filled = p.fill().is_some_and(|f| palette(f.paint()));
                if !(stroked || filled) {
                    continue;
                }
                let curved = p.data().segments().any(|s| {
                    matches!(
                        s,
                        usvg::tiny_skia_path::PathSegment::CubicTo(..)
                            | usvg::tiny_skia_path::PathSegment::QuadTo(..)
                    )
                });
                if filled || curved {
                    out.marks.push(p.abs_bounding_box());
                } else {
                    let mut pts = p.data().points().to_vec();
                    p.abs_transform().map_points(&mut pts);
                    out.segments.extend(pts.windows(2).map(|w| (w[0], w[1])));
                }
            }
            _ => {}
        }
    }
}

fn drawn(svg: &str) -> Drawn {
    let tree = usvg::Tree::from_str(svg, mbd::output::raster::options()).expect("a valid SVG");
    let mut d = Drawn {
        size: (tree.size().width(), tree.size().height()),
        ..Drawn::default()
    };
    walk(tree.root(), false, &mut d);
    d
}

fn overlap(a: &Rect, b: &Rect) -> bool {
    // Half a pixel of slack: boxes that touch do not overlap.
    a.left() < b.right() - 0.5
        && b.left() < a.right() - 0.5
        && a.top() < b.bottom() - 0.5
        && b.top() < a.bottom() - 0.5
}

/// Whether the segment crosses the rectangle (Liang-Barsky clipping).
fn crosses(&(p, q): &(Point, Point), r: &Rect) -> bool {
    let (dx, dy) = (q.x - p.x, q.y - p.y);
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for (den, num) in [
        (-dx, p.x - r.left()),
        (dx, r.right() - p.x),
        (-dy, p.y - r.top()),
        (dy, r.bottom() - p.y),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return false;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    t0 < t1
}

/// The significant digits of a number as written: `0.0125` has 3, `1e-6` one.
fn significant(label: &str) -> usize {
    let mantissa = label
        .trim_start_matches('-')
        .split('e')
        .next()
        .unwrap_or("");
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    digits
        .trim_start_matches('0')
        .trim_end_matches('0')
        .len()
        .max(1)
}

/// The checks every chart passes; with `reference`, its PNG is compared with the stored image
/// of that name.
pub fn check(svg: &str, reference: Option<&str>) {
    let d = drawn(svg);
    assert!(!d.texts.is_empty(), "no text drawn");
    assert!(
        !d.segments.is_empty() || !d.marks.is_empty(),
        "no data drawn"
    );
    let (w, h) = d.size;
    for t in &d.texts {
        let r = &t.rect;
        assert!(
            r.left() >= 0.0 && r.top() >= 0.0 && r.right() <= w && r.bottom() <= h,
            "`{}` clipped at {r:?}",
            t.text
        );
        for data in &d.segments {
            assert!(!crosses(data, r), "`{}` over the data", t.text);
        }
        for m in &d.marks {
            assert!(!overlap(m, r), "`{}` over the data at {m:?}", t.text);
        }
    }
    for (i, a) in d.texts.iter().enumerate() {
        for b in &d.texts[i + 1..] {
            assert!(
                !overlap(&a.rect, &b.rect),
                "`{}` and `{}` overlap: {:?} {:?}",
                a.text,
                b.text,
                a.rect,
                b.rect
            );
        }
    }
    assert!(!d.legends.is_empty(), "no legend");
    for l in &d.legends {
        assert!(
            d.segments.iter().all(|s| !crosses(s, l)),
            "legend over a line"
        );
        assert!(
            d.marks.iter().all(|m| !overlap(m, l)),
            "legend over a marker"
        );
    }
    ticks(&d);
    if let Some(name) = reference {
        compare(name, svg);
    }
}

/// Tick labels: the numeric texts outside the legends. An x axis is a row of them at one
/// height, a y axis a column with one right edge; each reads in order, with at most three
/// significant digits, and has at least two.
fn ticks(d: &Drawn) {
    let numbers: Vec<(&Text, f64)> = d
        .texts
        .iter()
        .filter(|t| !t.legend)
        .filter_map(|t| Some((t, t.text.parse::<f64>().ok()?)))
        .collect();
    assert!(numbers.len() >= 4, "fewer than two ticks per axis");
    for (t, _) in &numbers {
        assert!(significant(&t.text) <= 3, "`{}`: over 3 digits", t.text);
        assert!(!t.text.starts_with("-0") || t.text.starts_with("-0."), "-0");
    }
    // Rows keyed by their centre height hold (left, value); columns keyed by their right
    // edge hold (top, value).
    let centre = |t: &Text| (t.rect.top() + t.rect.bottom()) / 2.0;
    let mut rows: Vec<(f32, Vec<(f32, f64)>)> = Vec::new();
    let mut columns: Vec<(f32, Vec<(f32, f64)>)> = Vec::new();
    for (t, v) in &numbers {
        let y = centre(t);
        let in_row = numbers
            .iter()
            .any(|(o, _)| !std::ptr::eq(*o, *t) && (centre(o) - y).abs() < 1.0);
        let (groups, key, at) = if in_row {
            (&mut rows, y, t.rect.left())
        } else {
            (&mut columns, t.rect.right(), t.rect.top())
        };
        match groups.iter_mut().find(|(k, _)| (k - key).abs() < 1.5) {
            Some((_, list)) => list.push((at, *v)),
            None => groups.push((key, vec![(at, *v)])),
        }
    }
    assert!(!rows.is_empty(), "no x axis labels");
    assert!(!columns.is_empty(), "no y axis labels");
    for (_, r) in &mut rows {
        r.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(r.len() >= 2, "an x axis with one label: {r:?}");
        assert!(
            r.windows(2).all(|w| w[0].1 < w[1].1),
            "x labels out of order: {r:?}"
        );
    }
    // Stacked panels share the y labels' right edge: each label belongs to the panel whose
    // x labels are the first row below it.
    let mut below: Vec<f32> = rows.iter().map(|(y, _)| *y).collect();
    below.sort_by(f32::total_cmp);
    for (_, c) in &mut columns {
        c.sort_by(|a, b| a.0.total_cmp(&b.0));
        let panel = |top: f32| below.iter().position(|&y| y > top);
        for (k, part) in c.chunk_by(|a, b| panel(a.0) == panel(b.0)).enumerate() {
            assert!(part.len() >= 2, "a y axis with one label: {part:?} ({k})");
            assert!(
                part.windows(2).all(|w| w[0].1 > w[1].1),
                "y labels out of order: {part:?}"
            );
        }
    }
}

/// The PNG against `tests/charts/NAME.png`: the share of pixels differing by more than a
/// quarter of the range in some channel.
fn compare(name: &str, svg: &str) {
    let png = mbd::output::raster::png(svg).expect("a PNG");
    let path = repo(&format!("tests/charts/{name}.png"));
    if std::env::var_os("MBD_BLESS_CHARTS").is_some() {
        std::fs::create_dir_all(path.parent().expect("dir")).expect("dir");
        std::fs::write(&path, &png).expect("write the reference");
        return;
    }
    let stored = std::fs::read(&path).unwrap_or_else(|_| {
        panic!("no reference image {path:?}: run with MBD_BLESS_CHARTS=1 and review it")
    });
    let (a, b) = (
        Pixmap::decode_png(&png).expect("our PNG"),
        Pixmap::decode_png(&stored).expect("the stored PNG"),
    );
    assert_eq!(
        (a.width(), a.height()),
        (b.width(), b.height()),
        "{name}: size"
    );
    let differ = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .filter(|(p, q)| {
            let d = |x: u8, y: u8| x.abs_diff(y) > 64;
            d(p.red(), q.red()) || d(p.green(), q.green()) || d(p.blue(), q.blue())
        })
        .count();
    let share = differ as f64 / a.pixels().len() as f64;
    // Measured 0 on the machine that stored them; the bound allows a changed last bit of the
    // data moving an antialiased line edge (a curve of 800 px touches ~0.3 % of the pixels).
    within(&format!("{name}: pixels changed"), share, 3e-3);
}

fn row(integrator: &str, steps: usize, cpu: f64, error: f64) -> Row {
    Row {
        integrator: integrator.to_string(),
        dt: 1.0 / steps as f64,
        steps,
        error: Some(error),
        cpu_s: Some(cpu),
        newton_iterations: Some(steps),
        failure: None,
    }
}

/// A work-precision chart of fixed data: a second- and a fourth-order integrator.
#[test]
fn the_work_precision_chart_has_order_guides_and_target_lines() {
    let mut rows = Vec::new();
    for k in 0..6 {
        let n = 50usize << k;
        let cpu = 2e-4 * n as f64;
        rows.push(row("hht:-0.1", n, cpu, 3.0 / (n * n) as f64));
        rows.push(row("fet4", n, 1.5 * cpu, 40.0 / (n as f64).powi(4)));
    }
    let study = Convergence { rows, finest: None };
    let chart = study.chart("pendulum", "x");
    assert!(chart.title.contains("relative error of x against CPU time"));
    let labels: Vec<&str> = chart.series.iter().map(|s| s.label.as_str()).collect();
    assert_eq!(labels, ["hht:-0.1: order 2.00", "fet4: order 4.00"]);
    let guides: Vec<&str> = chart.guides.iter().map(|g| g.label.as_str()).collect();
    assert_eq!(
        guides,
        [
            "order 2: error ~ CPU^-2",
            "order 4: error ~ CPU^-4",
            "target errors",
            "target errors"
        ]
    );
    let svg = charts::render(&chart).expect("drawn");
    check(&svg, Some("work_precision"));
    // Decades as 1e-N, the two target errors drawn and named once.
    let d = drawn(&svg);
    let texts: Vec<&str> = d.texts.iter().map(|t| t.text.as_str()).collect();
    for want in ["1e-6", "1e-8", "target errors", "order 2: error ~ CPU^-2"] {
        assert!(texts.contains(&want), "{want} missing from {texts:?}");
    }
    assert_eq!(texts.iter().filter(|t| **t == "target errors").count(), 1);
}

/// The stability study's chart: |channel| on a log axis over time, one run per alpha.
#[test]
fn the_growth_chart_reads_on_a_log_axis() {
    let samples = |rate: f64| mbd::study::compare::Samples {
        t: (0..=400).map(|k| k as f64 * 0.05).collect(),
        y: (0..=400)
            .map(|k| {
                let t = k as f64 * 0.05;
                1e-6 * (rate * t).exp() * (3.0 * t).sin()
            })
            .collect(),
    };
    let rows: Vec<StabilityRow> = [(0.0, 0.6), (-0.1, 0.2)]
        .iter()
        .map(|&(alpha, rate)| StabilityRow {
            alpha,
            dt: 0.05,
            steps: 400,
            onset: None,
            failed: None,
            cpu_s: None,
            newton_iterations: None,
            failure: None,
            samples: samples(rate),
        })
        .collect();
    let chart = stability::chart(&rows, "two_bar", "ayc2");
    assert!(chart.title.contains("growth of |ayc2|"), "{}", chart.title);
    let svg = charts::render(&chart).expect("drawn");
    check(&svg, Some("growth"));
}

/// Many series, long labels and a narrow range: the legend is cut, the ticks thinned.
#[test]
fn crowded_charts_keep_their_labels_apart() {
    let series: Vec<charts::Series> = (0..30)
        .map(|k| charts::Series {
            label: format!("a rather long series label number {k} of the chart"),
            points: (0..50)
                .map(|i| (1.0 + i as f64 * 1e-3, (k as f64 + i as f64 * 0.1).sin()))
                .collect(),
            markers_only: false,
        })
        .collect();
    let mut chart = Chart::new("crowded", "x", "y", series.clone());
    check(&charts::render(&chart).expect("drawn"), None);
    chart.log_x = true;
    check(&charts::render(&chart).expect("drawn"), None);
    let stack = [
        chart.clone(),
        Chart::new("", "x", "y", series[..3].to_vec()),
    ];
    check(&charts::render_stack(&stack).expect("drawn"), None);
}

#[test]
fn png_and_svg_by_extension() {
    let chart = Chart::new(
        "t",
        "x",
        "y",
        vec![charts::Series {
            label: "s".into(),
            points: vec![(0.0, 1.0), (1.0, 2.0)],
            markers_only: false,
        }],
    );
    let png = charts::encode(std::slice::from_ref(&chart), "a/b.PNG").expect("png");
    assert!(png.starts_with(b"\x89PNG"));
    let svg = charts::encode(std::slice::from_ref(&chart), "b.svg").expect("svg");
    assert!(svg.starts_with(b"<svg"));
}
