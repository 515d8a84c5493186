//! Joints whose equations are redundant but consistent (W0303): the run has dropped their
//! surplus rows, so their multipliers are one split of the loads the loop carries. The
//! reported reactions are the minimum-norm split instead: the rows' forces `mu` with the
//! same generalized force `G^T mu` and the least `|S mu|` (`S` is 1 on rows of force units
//! and `1 / length` on rows of moment units, so both weigh alike). Also: how far the dropped
//! rows have drifted, the check that the redundancy stays consistent along the motion.

use super::{Geo, Joint, Row, SLOTS, TB, UB};
use crate::runtime::rotation::V3;
use crate::runtime::{Augment, Element, State};
use nalgebra::{DMatrix, DVector};
use std::collections::HashMap;

impl Joint {
    /// Each row's gradient over the joint's slots and its force; `None` for a joint with an
    /// end between beam nodes (its slots reach several unknowns).
    fn rows_and_forces(&self, st: &State, aug: Augment) -> Option<Vec<(super::Grad, f64, &Row)>> {
        if self.a.is_between() || self.b.is_between() {
            return None;
        }
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        Some(
            self.rows
                .iter()
                .enumerate()
                .map(|(k, row)| (row.geom(&geo).1, self.multiplier_force(st, aug, k), row))
                .collect(),
        )
    }

    /// The largest violation of a dropped row (m, or rad for an axis).
    pub fn dropped_violation(&self, st: &State) -> f64 {
        (0..self.rows.len())
            .filter(|&k| self.is_dropped(k, st))
            .map(|k| self.violation_row(st, k).abs())
            .fold(0.0, f64::max)
    }

    /// The reaction on end B from the row forces `mu`, as [`Joint::reaction`] gives it.
    fn reaction_from(&self, st: &State, mu: &[f64]) -> (V3, V3) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let (mut f, mut m) = (V3::zeros(), V3::zeros());
        for (row, &mu) in self.rows.iter().zip(mu) {
            let (_, gr) = row.geom(&geo);
            f -= V3::new(gr[UB], gr[UB + 1], gr[UB + 2]) * mu;
            m -= V3::new(gr[TB], gr[TB + 1], gr[TB + 2]) * mu;
        }
        (f, m - geo.b.p.cross(&f))
    }
}

/// Whether a row's force is a moment (its equation is dimensionless: axes, angles).
fn is_moment(row: &Row) -> bool {
    matches!(
        row,
        Row::Dot { .. } | Row::Angle | Row::AngleDrive { .. } | Row::Phi
    )
}

/// The reaction of joint element `which` with the forces of the joints `group` (element
/// indices, `which` among them) split by minimum norm; `None` if a joint of the group has an
/// end between beam nodes (then its own split stands).
pub fn min_norm_reaction(
    elements: &[Element],
    group: &[usize],
    which: usize,
    st: &State,
    aug: Augment,
    length: f64,
) -> Option<(V3, V3)> {
    let mu = min_norm_forces(elements, group, which, st, aug, length)?;
    let Element::Joint(j) = &elements[which] else {
        return None;
    };
    Some(j.reaction_from(st, &mu))
}

/// The row forces of joint element `which` in the minimum-norm split of the group's.
pub fn min_norm_forces(
    elements: &[Element],
    group: &[usize],
    which: usize,
    st: &State,
    aug: Augment,
    length: f64,
) -> Option<Vec<f64>> {
    let mut joints = Vec::new();
    for &e in group {
        let Element::Joint(j) = &elements[e] else {
            return None;
        };
        joints.push((e, j, j.rows_and_forces(st, aug)?));
    }
    // Rows (rate rows keep their forces) over the group's unknowns.
    let mut column: HashMap<usize, usize> = HashMap::new();
    // (joint in the group, row, entries, force, weight)
    let mut rows: Vec<(usize, usize, Entries, f64, f64)> = Vec::new();
    for (g, (_, j, list)) in joints.iter().enumerate() {
        let slots = super::globals(&j.a, &j.b, j.angle);
        for (k, (gr, mu, row)) in list.iter().enumerate() {
            let entries: Vec<(usize, f64)> = (0..SLOTS)
                .filter_map(|s| slots[s].map(|i| (i, gr[s])))
                .filter(|&(_, v)| v != 0.0)
                .map(|(i, v)| {
                    let n = column.len();
                    (*column.entry(i).or_insert(n), v)
                })
                .collect();
            if row.is_rate() {
                continue;
            }
            let scale = if is_moment(row) { 1.0 / length } else { 1.0 };
            rows.push((g, k, entries, *mu, scale));
        }
    }
    let (nr, nc) = (rows.len(), column.len());
    // F = G^T mu; nu = S mu minimizes |nu| with (G^T S^-1) nu = F.
    let mut gts = DMatrix::<f64>::zeros(nc, nr);
    let mut force = DVector::<f64>::zeros(nc);
    for (r, (_, _, entries, mu, scale)) in rows.iter().enumerate() {
        for &(c, v) in entries {
            gts[(c, r)] += v / scale;
            force[c] += v * mu;
        }
    }
    let svd = gts.svd(true, true);
    let top = svd.singular_values.amax();
    let nu = svd.solve(&force, 1e-12 * top).ok()?;
    let at = joints.iter().position(|(e, _, _)| *e == which)?;
    let mut mu: Vec<f64> = joints[at].2.iter().map(|(_, m, _)| *m).collect();
    for (r, (g, k, _, _, scale)) in rows.iter().enumerate() {
        if *g == at {
            mu[*k] = nu[r] / scale;
        }
    }
    Some(mu)
}

/// The rows to drop among those of the redundant joints `group` (element indices) at `st`:
/// their gradients (rotation columns divided by `length`, to weigh like translations), each
/// made unit, by pivoted Gram-Schmidt: at each stage the row with the largest remainder is
/// kept and projected out of the others. The `count` rows left are dropped, or, with `None`,
/// every row whose remainder is below 1e-9 (the rows the kept ones span). Rate rows are
/// always kept. One mask per joint of the group.
pub fn select_dropped(
    elements: &[Element],
    group: &[usize],
    unknowns: &[crate::runtime::UnknownKind],
    st: &State,
    length: f64,
    count: Option<usize>,
) -> Vec<u16> {
    let (rows, dense) = unit_rows(elements, group, unknowns, st, length);
    let count = count.map(|c| c.min(rows.len()));
    let (masks, worst) = pivoted(&rows, dense.clone(), group.len(), count, None);
    // Hysteresis: the rows dropped now stay dropped while the rows they keep are at least a
    // quarter as far apart as the best choice's (switching at every tie would drop a row
    // the step has just been solved with).
    if count.is_some() && st.dropped.len() == group.len() && masks != st.dropped {
        let (_, now) = pivoted(&rows, dense, group.len(), count, Some(&st.dropped));
        if now >= 0.25 * worst {
            return st.dropped.clone();
        }
    }
    masks
}

/// A row's entries: (column, value).
type Entries = Vec<(usize, f64)>;

/// A row of the group: its joint (index in the group), its row, its entries.
type GroupRow = (usize, usize, Entries);

/// The group's position rows over their unknowns, each made unit (rotations divided by
/// `length`).
fn unit_rows(
    elements: &[Element],
    group: &[usize],
    unknowns: &[crate::runtime::UnknownKind],
    st: &State,
    length: f64,
) -> (Vec<GroupRow>, Vec<Vec<f64>>) {
    let mut column: HashMap<usize, usize> = HashMap::new();
    let mut rows: Vec<GroupRow> = Vec::new();
    for (g, &e) in group.iter().enumerate() {
        let Element::Joint(j) = &elements[e] else {
            continue;
        };
        let geo = Geo::new(&j.a, &j.b, j.angle, st);
        let spread = (j.a.is_between() || j.b.is_between())
            .then(|| super::ends::Spreads::new(&j.a, &j.b, j.angle, st));
        let slots = match spread {
            None => super::globals(&j.a, &j.b, j.angle),
            Some(_) => [None; SLOTS],
        };
        let locals = j.indices();
        for (k, row) in j.rows.iter().enumerate() {
            if row.is_rate() {
                continue;
            }
            let (_, gr) = row.geom(&geo);
            let mut entries: Vec<(usize, f64)> = Vec::new();
            for s in 0..SLOTS {
                if gr[s] == 0.0 {
                    continue;
                }
                let targets: Vec<(usize, f64)> = match &spread {
                    None => slots[s].map(|i| vec![(i, 1.0)]).unwrap_or_default(),
                    Some(sp) => sp.trial[s].iter().map(|(l, c)| (locals[l], c)).collect(),
                };
                for (i, c) in targets {
                    let scale = match unknowns[i] {
                        crate::runtime::UnknownKind::Rotation { .. } => {
                            length.max(f64::MIN_POSITIVE)
                        }
                        _ => 1.0,
                    };
                    let n = column.len();
                    entries.push((*column.entry(i).or_insert(n), gr[s] * c / scale));
                }
            }
            rows.push((g, k, entries));
        }
    }
    let width = column.len();
    let dense: Vec<Vec<f64>> = rows
        .iter()
        .map(|(_, _, entries)| {
            let mut v = vec![0.0; width];
            entries.iter().for_each(|&(c, x)| v[c] += x);
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 0.0 {
                v.iter_mut().for_each(|x| *x /= n);
            }
            v
        })
        .collect();
    (rows, dense)
}

/// Pivoted Gram-Schmidt over `dense` (rows of `rows`), among the rows not dropped by `only`
/// if given: the masks of the rows left and the smallest remainder of a row kept.
fn pivoted(
    rows: &[GroupRow],
    mut dense: Vec<Vec<f64>>,
    joints: usize,
    count: Option<usize>,
    only: Option<&[u16]>,
) -> (Vec<u16>, f64) {
    let dropped_now = |i: usize| only.is_some_and(|m| m[rows[i].0] & (1 << rows[i].1) != 0);
    let mut left: Vec<usize> = (0..rows.len()).collect();
    let keep = count.map(|c| rows.len().saturating_sub(c));
    let (mut kept, mut worst) = (0, f64::INFINITY);
    while !left.is_empty() && keep.is_none_or(|k| kept < k) {
        let norm = |i: usize| dense[i].iter().map(|x| x * x).sum::<f64>().sqrt();
        let (at, best) = left
            .iter()
            .enumerate()
            .filter(|&(_, &i)| !dropped_now(i))
            .map(|(at, &i)| (at, norm(i)))
            .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
        // A row with nothing left is spanned whatever the count asks.
        if best <= 0.0 || (count.is_none() && best <= 1e-9) {
            break;
        }
        worst = worst.min(best);
        let i = left.swap_remove(at);
        let q: Vec<f64> = dense[i].iter().map(|x| x / best).collect();
        for &o in &left {
            let d: f64 = q.iter().zip(&dense[o]).map(|(a, b)| a * b).sum();
            dense[o].iter_mut().zip(&q).for_each(|(x, a)| *x -= d * a);
        }
        kept += 1;
    }
    let mut masks = vec![0u16; joints];
    for i in left {
        let (g, k, _) = rows[i];
        masks[g] |= 1 << k;
    }
    (masks, worst)
}
