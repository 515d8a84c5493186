//! A sweep's modes followed along its grid ([`crate::study::tracking`]): the CSV's columns per
//! followed mode and the Campbell diagram.

use super::{Method, Point, Sweep};
use crate::output::charts::{Chart, Series};
use crate::solve::modes::c64;
use crate::study::tracking::{campbell, Column, Tracker};
use std::io::{self, Write};

/// Gives every mode of the grid's points its track: per method, along the grid's order.
pub(super) fn follow(points: &mut [Point]) {
    let mut follower = Follower::default();
    for p in points.iter_mut() {
        follower.next(p);
    }
}

/// The tracks of each method so far, point by point along the grid.
#[derive(Default)]
pub(super) struct Follower {
    trackers: Vec<(Method, Tracker)>,
}

impl Follower {
    /// The tracks of the next point's modes (none for a failed point).
    pub(super) fn next(&mut self, p: &mut Point) {
        if p.failure.is_some() {
            return;
        }
        let k = match self.trackers.iter().position(|(m, _)| *m == p.method) {
            Some(k) => k,
            None => {
                self.trackers.push((p.method, Tracker::new()));
                self.trackers.len() - 1
            }
        };
        let keys: Vec<(c64, &[c64])> = (p.modes.iter().enumerate())
            .map(|(i, s)| (*s, p.shapes.get(i).map_or(&[][..], |v| &v[..])))
            .collect();
        p.tracks = self.trackers[k].1.follow(&keys);
    }
}

/// The most tracks of any method.
pub(super) fn count(points: &[Point]) -> usize {
    points
        .iter()
        .flat_map(|p| p.tracks.iter().map(|t| t + 1))
        .max()
        .unwrap_or(0)
}

/// A row's cells per track: `,freq,real,damping` (empty where the track has no mode here).
pub(super) fn write_row(p: &Point, tracks: usize, out: &mut dyn Write) -> io::Result<()> {
    for t in 0..tracks {
        match p.tracks.iter().position(|&k| k == t) {
            Some(i) if p.failure.is_none() => {
                let s = p.modes[i];
                let r = s.re.hypot(s.im);
                let zeta = if r > 0.0 { -s.re / r } else { 0.0 };
                write!(out, ",{},{},{}", s.im, s.re, zeta)?;
            }
            _ => write!(out, ",,,")?,
        }
    }
    Ok(())
}

impl Sweep {
    /// The Campbell diagram of the primary method's grid ([`campbell`]): each followed mode's
    /// frequency with the per-rev lines, and its real part with the unstable ranges shaded;
    /// another method's real parts as markers, and `reference` series, on the lower panel.
    pub fn campbell(&self, title: &str, reference: Vec<Series>) -> Vec<Chart> {
        let Some(primary) = self.points.first().map(|p| p.method) else {
            return campbell(title, &self.param, &[], 0, Vec::new(), reference);
        };
        let ok = || self.points.iter().filter(|p| p.failure.is_none());
        let columns: Vec<Column> = ok()
            .filter(|p| p.method == primary)
            .map(|p| Column {
                value: p.value,
                rotor_speed: p.rotor_speed,
                modes: p
                    .tracks
                    .iter()
                    .copied()
                    .zip(p.modes.iter().copied())
                    .collect(),
            })
            .collect();
        let tracks = columns
            .iter()
            .flat_map(|c| c.modes.iter().map(|(t, _)| t + 1))
            .max()
            .unwrap_or(0);
        let mut extra: Vec<Series> = Vec::new();
        for p in ok().filter(|p| p.method != primary) {
            let label = format!("Re s of each mode ({})", p.method.name());
            let k = match extra.iter().position(|s| s.label == label) {
                Some(k) => k,
                None => {
                    extra.push(Series {
                        label,
                        points: Vec::new(),
                        markers_only: true,
                    });
                    extra.len() - 1
                }
            };
            extra[k]
                .points
                .extend(p.modes.iter().map(|s| (p.value, s.re)));
        }
        extra.extend(reference);
        campbell(
            title,
            &self.param,
            &columns,
            tracks,
            self.unstable_ranges(),
            extra,
        )
    }
}
