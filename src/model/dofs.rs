//! Numbering of the unknowns.
//!
//! Invariant: every multiplier comes right after the last unknown it couples, so eliminating
//! it meets a non-zero pivot (THEORY §6) and the factorization needs no pivoting.

use super::{Attach, Body, Joint};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Unknown {
    /// Displacement of a body along inertial axis 0, 1 or 2.
    Translation { body: usize, axis: usize },
    /// Row `row` of a joint's multipliers.
    Multiplier { joint: usize, row: usize },
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct DofMap {
    pub unknowns: Vec<Unknown>,
    /// First unknown of each body (three in a row).
    pub body_start: Vec<usize>,
    /// First multiplier of each joint.
    pub joint_start: Vec<usize>,
    /// Largest distance from the diagonal of a coupling in the iteration matrix.
    pub bandwidth: usize,
}

impl DofMap {
    pub fn new(bodies: &[Body], joints: &[Joint]) -> DofMap {
        let mut map = DofMap {
            body_start: vec![0; bodies.len()],
            joint_start: vec![0; joints.len()],
            ..Default::default()
        };
        let last_body = |j: &Joint| {
            j.markers
                .iter()
                .filter_map(|m| match m.attach {
                    Attach::Body(b) => Some(b),
                    Attach::Ground(_) => None,
                })
                .max()
        };
        for b in 0..bodies.len() {
            map.body_start[b] = map.unknowns.len();
            map.unknowns
                .extend((0..3).map(|axis| Unknown::Translation { body: b, axis }));
            for (ji, j) in joints.iter().enumerate() {
                if last_body(j) == Some(b) {
                    map.joint_start[ji] = map.unknowns.len();
                    map.unknowns.extend(
                        (0..j.kind.multipliers()).map(|row| Unknown::Multiplier { joint: ji, row }),
                    );
                }
            }
        }
        for (ji, j) in joints.iter().enumerate() {
            let mut idx: Vec<usize> = (0..j.kind.multipliers())
                .map(|r| map.joint_start[ji] + r)
                .collect();
            for m in &j.markers {
                if let Attach::Body(b) = m.attach {
                    idx.extend((0..3).map(|a| map.body_start[b] + a));
                }
            }
            let (lo, hi) = (
                idx.iter().min().copied().unwrap_or(0),
                idx.iter().max().copied().unwrap_or(0),
            );
            map.bandwidth = map.bandwidth.max(hi - lo);
        }
        map.bandwidth = map.bandwidth.max(if bodies.is_empty() { 0 } else { 2 });
        map
    }

    pub fn len(&self) -> usize {
        self.unknowns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.unknowns.is_empty()
    }

    pub fn multipliers(&self) -> usize {
        self.unknowns
            .iter()
            .filter(|u| matches!(u, Unknown::Multiplier { .. }))
            .count()
    }
}
