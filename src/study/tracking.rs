//! Modes followed along a swept param, and their Campbell diagram: shared by fan plots
//! (`mbd modes --sweep`) and stability sweeps (`mbd stability`).
//!
//! Contract: [`Tracker::follow`] gives each mode of the next point the track (a stable id,
//! 0-based) whose last mode it continues: first by shape, pairs of decreasing modal assurance
//! criterion (MAC >= [`MAC_MIN`]) where both carry a shape; then the modes left by their
//! exponent, the nearest within [`NEAR`] of its modulus; a mode matching no track starts one.
//! [`campbell`] draws two panels over one param axis: each track's frequency with the
//! per-revolution lines `n Omega`, and its real part with the unstable ranges shaded. Must not
//! read or write files.

use crate::output::charts::{Chart, Series};
use crate::solve::modes::c64;

/// Shapes correlated at least this well continue one mode.
pub const MAC_MIN: f64 = 0.5;

/// Without a shape match, exponents within this share of their modulus continue one mode.
pub const NEAR: f64 = 0.2;

/// The modal assurance criterion `|a^H b|^2 / (|a|^2 |b|^2)` of two shapes (0 when either is
/// empty or zero, or their lengths differ).
pub fn mac(a: &[c64], b: &[c64]) -> f64 {
    if a.len() != b.len() {
        return 0.0;
    }
    let (mut re, mut im, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        re += x.re * y.re + x.im * y.im;
        im += x.re * y.im - x.im * y.re;
        na += x.re * x.re + x.im * x.im;
        nb += y.re * y.re + y.im * y.im;
    }
    if na == 0.0 || nb == 0.0 {
        0.0
    } else {
        (re * re + im * im) / (na * nb)
    }
}

/// The last exponent and shape of each track.
#[derive(Clone, Debug, Default)]
pub struct Tracker {
    last: Vec<(c64, Vec<c64>)>,
}

impl Tracker {
    pub fn new() -> Tracker {
        Tracker::default()
    }

    /// The number of tracks so far.
    pub fn tracks(&self) -> usize {
        self.last.len()
    }

    /// The track of each mode `(s, shape)` of the next point (an empty shape: match by the
    /// exponent only).
    pub fn follow(&mut self, modes: &[(c64, &[c64])]) -> Vec<usize> {
        let mut track = vec![usize::MAX; modes.len()];
        let mut taken = vec![false; self.last.len()];
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, (_, shape)) in modes.iter().enumerate() {
            for (t, (_, last)) in self.last.iter().enumerate() {
                let m = mac(shape, last);
                if m >= MAC_MIN {
                    pairs.push((m, i, t));
                }
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
        assign(&pairs, &mut track, &mut taken);
        // The rest by the exponent: the nearest first.
        let mut near: Vec<(f64, usize, usize)> = Vec::new();
        for (i, (s, _)) in modes
            .iter()
            .enumerate()
            .filter(|(i, _)| track[*i] == usize::MAX)
        {
            for (t, (l, _)) in self.last.iter().enumerate().filter(|(t, _)| !taken[*t]) {
                let d = (s.re - l.re).hypot(s.im - l.im);
                let scale = s.re.hypot(s.im).max(l.re.hypot(l.im));
                if d <= NEAR * scale {
                    near.push((-d, i, t));
                }
            }
        }
        near.sort_by(|a, b| b.0.total_cmp(&a.0));
        assign(&near, &mut track, &mut taken);
        for (i, (s, shape)) in modes.iter().enumerate() {
            if track[i] == usize::MAX {
                self.last.push((*s, Vec::new()));
                track[i] = self.last.len() - 1;
            }
            let last = &mut self.last[track[i]];
            last.0 = *s;
            last.1.clear();
            last.1.extend_from_slice(shape);
        }
        track
    }
}

/// Greedy assignment along `pairs` `(score, mode, track)`, best first.
fn assign(pairs: &[(f64, usize, usize)], track: &mut [usize], taken: &mut [bool]) {
    for &(_, i, t) in pairs {
        if track[i] == usize::MAX && !taken[t] {
            track[i] = t;
            taken[t] = true;
        }
    }
}

/// One point of a Campbell diagram: the param's value, the rotor speed there (rad/s; NaN
/// when the model does not spin), and the exponent of each track present (`(track, s)`, the
/// frequency `Im s >= 0` in rad/s).
#[derive(Clone, Debug)]
pub struct Column {
    pub value: f64,
    pub rotor_speed: f64,
    pub modes: Vec<(usize, c64)>,
}

/// The Campbell diagram: frequency against the param, one line per track with the per-rev
/// lines `n Omega` (up to the highest frequency, at most 8), and the real parts below,
/// `shaded` (the unstable ranges) on both panels; `extra` series (markers of another method)
/// go on the real parts' panel.
pub fn campbell(
    title: &str,
    param: &str,
    columns: &[Column],
    tracks: usize,
    shaded: Vec<(f64, f64)>,
    extra: Vec<Series>,
) -> Vec<Chart> {
    let line = |t: usize, pick: &dyn Fn(c64) -> f64| Series {
        label: format!("mode {}", t + 1),
        points: columns
            .iter()
            .flat_map(|c| {
                c.modes
                    .iter()
                    .filter(move |(k, _)| *k == t)
                    .map(move |(_, s)| (c.value, pick(*s)))
            })
            .collect(),
        markers_only: false,
    };
    let mut freq: Vec<Series> = (0..tracks).map(|t| line(t, &|s| s.im)).collect();
    let real: Vec<Series> = (0..tracks).map(|t| line(t, &|s| s.re)).collect();
    let top = columns
        .iter()
        .flat_map(|c| c.modes.iter().map(|(_, s)| s.im))
        .fold(0.0f64, f64::max);
    let spinning: Vec<&Column> = columns
        .iter()
        .filter(|c| c.rotor_speed.is_finite())
        .collect();
    let fastest = spinning
        .iter()
        .map(|c| c.rotor_speed)
        .fold(0.0f64, f64::max);
    if fastest > 0.0 && top > 0.0 {
        let revs = ((top / fastest).ceil() as usize).clamp(1, 8);
        for n in 1..=revs {
            freq.push(Series {
                label: format!("{n}/rev"),
                points: spinning
                    .iter()
                    .map(|c| (c.value, n as f64 * c.rotor_speed))
                    .collect(),
                markers_only: false,
            });
        }
    }
    let mut upper = Chart::new(title, param, "frequency [rad/s]", freq);
    upper.shaded.clone_from(&shaded);
    let mut lower = Chart::new(title, param, "Re s [1/s]", real);
    lower.series.extend(extra);
    lower.shaded = shaded;
    vec![upper, lower]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mac_is_one_for_scaled_shapes_and_zero_for_orthogonal_ones() {
        let a = [c64::new(1.0, 0.0), c64::new(0.0, 2.0)];
        let b = [c64::new(0.0, 3.0), c64::new(-6.0, 0.0)];
        assert!((mac(&a, &b) - 1.0).abs() < 1e-15);
        let c = [c64::new(2.0, 0.0), c64::new(0.0, -1.0)];
        assert!(mac(&a, &c).abs() < 1e-15);
    }

    #[test]
    fn tracks_follow_shapes_through_a_crossing_and_exponents_without_shapes() {
        let (x, y) = (
            [c64::new(1.0, 0.0), c64::new(0.1, 0.0)],
            [c64::new(0.1, 0.0), c64::new(-1.0, 0.0)],
        );
        let mut t = Tracker::new();
        assert_eq!(
            t.follow(&[(c64::new(0.0, 1.0), &x), (c64::new(0.0, 2.0), &y)]),
            vec![0, 1]
        );
        // The frequencies cross; the shapes keep their tracks whatever the order.
        assert_eq!(
            t.follow(&[(c64::new(0.0, 1.5), &y), (c64::new(0.0, 1.6), &x)]),
            vec![1, 0]
        );
        // No shapes: the nearest exponent within NEAR; a far one starts a track.
        assert_eq!(
            t.follow(&[(c64::new(0.0, 9.0), &[]), (c64::new(0.0, 1.62), &[])]),
            vec![2, 0]
        );
        assert_eq!(t.tracks(), 3);
    }
}
