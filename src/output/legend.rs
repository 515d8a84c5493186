//! The title and the legend of a chart, written as SVG by hand (plotters' own legend sits
//! inside the plot): entries for the shade, each series and each guide, sized with the
//! bundled font's metrics, cut with an ellipsis when too long, summarised when too many.
//!
//! Contract: the legend of panel `k` is the SVG group `legend-k`, the title the text `title`.

use super::charts::{
    kept, Chart, Guide, GuideLine, GUIDE, LEGEND_MAX, LEGEND_ROW, LEGEND_SWATCH, PALETTE, SHADE,
    SHADE_OPACITY, TEXT, WIDTH,
};
use super::raster::{self, escape, FAMILY};
use plotters::style::RGBColor;
use std::fmt::Write as _;

fn hex(c: RGBColor) -> String {
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

/// The figure's title, centred, set smaller when it would not fit the width.
pub(super) fn title(text: &str, out: &mut String) {
    let width = raster::widths(&[text.to_string()], 16.0)[0];
    let room = WIDTH as f64 - 20.0;
    let size = if width > room {
        (16.0 * room / width).max(8.0)
    } else {
        16.0
    };
    let _ = write!(
        out,
        r#"<text id="title" x="{}" y="24" text-anchor="middle" font-family="{FAMILY}" font-size="{size:.2}">{}</text>"#,
        WIDTH / 2,
        escape(text)
    );
}

/// A legend entry's sample of what it names.
#[derive(Clone, Copy)]
enum Swatch {
    /// A line, with a marker when the series draws markers.
    Line(RGBColor, bool),
    Dot(RGBColor),
    Shade,
    /// Dashed (a slope) or dotted (a level).
    Guide(bool),
}

pub(super) struct Entry {
    label: String,
    swatch: Swatch,
}

/// The legend: the unstable shade, each series, each guide (one entry per distinct label).
pub(super) fn entries(
    chart: &Chart,
    shaded: bool,
    guides: &[(Guide, Vec<(f64, f64)>)],
) -> Vec<Entry> {
    let mut out = Vec::new();
    if shaded {
        out.push(Entry {
            label: "unstable".to_string(),
            swatch: Swatch::Shade,
        });
    }
    for (k, s) in chart.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let drawn = s
            .points
            .iter()
            .filter(|p| kept(p, chart.log_x, chart.log_y))
            .count();
        out.push(Entry {
            label: s.label.clone(),
            swatch: if s.markers_only {
                Swatch::Dot(colour)
            } else {
                Swatch::Line(colour, drawn <= MARKED)
            },
        });
    }
    for (g, _) in guides {
        if !out.iter().any(|e| e.label == g.label) {
            let dashed = matches!(g.line, GuideLine::Slope { .. });
            out.push(Entry {
                label: g.label.clone(),
                swatch: Swatch::Guide(dashed),
            });
        }
    }
    out
}

/// Series with at most this many points are drawn with markers (study charts).
pub(super) const MARKED: usize = 40;

/// `text`, cut with an ellipsis to at most `room` px.
fn fit(text: &str, width: f64, room: f64) -> String {
    if width <= room {
        return text.to_string();
    }
    let chars: Vec<char> = text.chars().collect();
    let (mut lo, mut hi) = (0, chars.len());
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        let cut: String = chars[..mid].iter().collect::<String>() + "…";
        if raster::widths(&[cut], TEXT)[0] <= room {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    chars[..lo].iter().collect::<String>() + "…"
}

/// The legend's width, and its entries with their labels fitted.
pub(super) fn legend_layout(entries: Vec<Entry>) -> (f64, Vec<Entry>) {
    if entries.is_empty() {
        return (0.0, entries);
    }
    let labels: Vec<String> = entries.iter().map(|e| e.label.clone()).collect();
    let widths = raster::widths(&labels, TEXT);
    let chrome = 8.0 + LEGEND_SWATCH + 6.0 + 8.0;
    let room = LEGEND_MAX - chrome;
    let fitted: Vec<Entry> = entries
        .into_iter()
        .zip(&widths)
        .map(|(e, &w)| Entry {
            label: fit(&e.label, w, room),
            swatch: e.swatch,
        })
        .collect();
    let widest = widths.iter().fold(0.0f64, |a, &w| a.max(w.min(room)));
    (widest + chrome, fitted)
}

/// Writes the legend of panel `k` as the SVG group `legend-k`, its top left at `(x, y)`,
/// fitting `room` px of height (entries beyond it summarised in a last row).
pub(super) fn legend(
    k: usize,
    entries: &[Entry],
    (x, y, w): (f64, f64, f64),
    room: f64,
    out: &mut String,
) {
    if entries.is_empty() {
        return;
    }
    // A line of text is 1.17 em high in this font.
    let min_row = (TEXT * 1.25).ceil();
    let fits = ((room - 8.0) / min_row).floor().max(1.0) as usize;
    let (shown, more) = if entries.len() <= fits {
        (entries.len(), 0)
    } else {
        (fits - 1, entries.len() + 1 - fits)
    };
    let rows = shown + usize::from(more > 0);
    let row = ((room - 8.0) / rows as f64).min(LEGEND_ROW);
    let h = rows as f64 * row + 8.0;
    let _ = write!(
        out,
        r##"<g id="legend-{k}" font-family="{FAMILY}" font-size="{TEXT}"><rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" fill="white" stroke="#b0b0b0"/>"##
    );
    let (sx, tx) = (x + 8.0, x + 8.0 + LEGEND_SWATCH + 6.0);
    for (i, e) in entries.iter().take(shown).enumerate() {
        let yc = y + 4.0 + (i as f64 + 0.5) * row;
        let line = |colour: &str, extra: &str| {
            format!(
                r#"<line x1="{sx:.1}" y1="{yc:.1}" x2="{:.1}" y2="{yc:.1}" stroke="{colour}" {extra}/>"#,
                sx + LEGEND_SWATCH
            )
        };
        let mid = sx + LEGEND_SWATCH / 2.0;
        let sample = match e.swatch {
            Swatch::Line(c, marked) => {
                let dot = if marked {
                    format!(
                        r#"<circle cx="{mid:.1}" cy="{yc:.1}" r="3" fill="{}"/>"#,
                        hex(c)
                    )
                } else {
                    String::new()
                };
                line(&hex(c), r#"stroke-width="2""#) + &dot
            }
            Swatch::Dot(c) => {
                format!(
                    r#"<circle cx="{mid:.1}" cy="{yc:.1}" r="3" fill="{}"/>"#,
                    hex(c)
                )
            }
            Swatch::Shade => format!(
                r#"<rect x="{sx:.1}" y="{:.1}" width="{LEGEND_SWATCH}" height="10" fill="{}" fill-opacity="{SHADE_OPACITY}"/>"#,
                yc - 5.0,
                hex(SHADE)
            ),
            Swatch::Guide(dashed) => line(
                &hex(GUIDE),
                if dashed {
                    r#"stroke-dasharray="6 4""#
                } else {
                    r#"stroke-dasharray="2 3""#
                },
            ),
        };
        let _ = write!(
            out,
            r#"{sample}<text x="{tx:.1}" y="{yc:.1}" dy="0.35em">{}</text>"#,
            escape(&e.label)
        );
    }
    if more > 0 {
        let yc = y + 4.0 + (shown as f64 + 0.5) * row;
        let _ = write!(
            out,
            r#"<text x="{sx:.1}" y="{yc:.1}" dy="0.35em">… and {more} more</text>"#
        );
    }
    out.push_str("</g>");
}
