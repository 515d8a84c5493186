//! Guide lines of a chart (slopes of convergence orders, target levels) and shaded ranges,
//! clipped to the plot's range.
//!
//! Contract: a guide is kept only when it crosses the plot; its two ends are returned in data
//! coordinates, straight in the axes' own scale (log-log: a power law).

use super::charts::{Chart, Guide, GuideLine};

/// A guide line and its two ends inside the plot.
pub(super) type Placed = (Guide, Vec<(f64, f64)>);

/// The shaded ranges and the guide lines clipped to the plot `[x0, x1] x [y0, y1]`.
pub(super) fn clipped(
    chart: &Chart,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> (Vec<(f64, f64)>, Vec<Placed>) {
    let (lx, ly) = (chart.log_x, chart.log_y);
    let shades: Vec<(f64, f64)> = chart
        .shaded
        .iter()
        .map(|&(a, b)| (a.max(x0), b.min(x1)))
        .filter(|(a, b)| b > a)
        .collect();
    let guides: Vec<Placed> = chart
        .guides
        .iter()
        .map(|g| (g.clone(), guide_ends(&g.line, (x0, x1), (y0, y1), lx && ly)))
        .filter(|(_, ends)| ends.len() == 2)
        .collect();
    (shades, guides)
}

/// Where a guide line crosses the plot `[x0, x1] x [y0, y1]`: its two ends, if it does.
fn guide_ends(
    g: &GuideLine,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    log: bool,
) -> Vec<(f64, f64)> {
    match *g {
        GuideLine::Level(y) => {
            if y > y0 && y < y1 {
                vec![(x0, y), (x1, y)]
            } else {
                Vec::new()
            }
        }
        GuideLine::Slope { through, slope } => {
            // A straight line in the axes' own coordinates (logarithms on log-log axes).
            type Map = fn(f64) -> f64;
            let (f, g): (Map, Map) = if log {
                (f64::ln, f64::exp)
            } else {
                (|v| v, |v| v)
            };
            let (u0, u1, v0, v1) = (f(x0), f(x1), f(y0), f(y1));
            let (uc, vc) = (f(through.0), f(through.1));
            if !(uc.is_finite() && vc.is_finite() && slope.is_finite()) {
                return Vec::new();
            }
            let v = |u: f64| vc + slope * (u - uc);
            let (mut a, mut b) = (u0, u1);
            if slope != 0.0 {
                let (ua, ub) = ((v0 - vc) / slope + uc, (v1 - vc) / slope + uc);
                a = a.max(ua.min(ub));
                b = b.min(ua.max(ub));
            } else if !(vc > v0 && vc < v1) {
                return Vec::new();
            }
            if b <= a {
                return Vec::new();
            }
            vec![(g(a), g(v(a))), (g(b), g(v(b)))]
        }
    }
}
