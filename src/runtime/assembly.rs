//! Assembly into a sparse pattern fixed once.
//!
//! Invariant: the compressed-column pattern and every element's scatter map are computed at
//! setup; assembling a Newton matrix writes values in place and allocates nothing.

use super::{Augment, Element, Rate, Residual, State, System, TangentCoeffs, UnknownKind};

/// A square compressed-column sparsity pattern (sorted row indices per column).
#[derive(Clone, Debug, PartialEq)]
pub struct Pattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
}

impl Pattern {
    /// The pattern of a system: each element's unknowns couple all pairwise, plus the diagonal.
    pub fn of(n: usize, elements: &[Element]) -> Pattern {
        let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
        for e in elements {
            let idx = e.indices();
            for &j in &idx {
                cols[j].extend_from_slice(&idx);
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend(c);
            col_ptr.push(row_idx.len());
        }
        Pattern {
            n,
            col_ptr,
            row_idx,
        }
    }

    /// Position of entry `(row, col)` in the value array.
    pub fn slot(&self, row: usize, col: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[col], self.col_ptr[col + 1]);
        self.row_idx[a..b].binary_search(&row).ok().map(|k| a + k)
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
}

/// Per element with inertia or damping: its index, and each frame among its unknowns with
/// the local positions of its translation and rotation unknowns.
type Rated = Vec<(usize, Vec<(usize, [usize; 6])>)>;

/// Assembles residuals and the iteration matrix of a [`System`].
pub struct Assembler {
    pub pattern: Pattern,
    /// Values of the iteration matrix, in pattern order.
    pub values: Vec<f64>,
    /// Per element: for local entry `i * nl + j` (row-major), the value slot.
    maps: Vec<Vec<usize>>,
    /// Per element: its unknowns (`Element::indices`), kept to assemble without allocating.
    indices: Vec<Vec<usize>>,
    local: Vec<f64>,
    local2: Vec<f64>,
    /// Per element with inertia or damping: the frames among its unknowns, each with the
    /// local positions of its translation and rotation unknowns.
    rated: Rated,
    /// The elements whose residual reads the rates ([`Element::reads_rates`]): those with
    /// inertia or damping, whose tangents split into `M` and `C` ([`Element::has_rates`]),
    /// and the rest (joints with rate rows).
    reading: (Vec<usize>, Vec<usize>),
    /// The unknowns of the elements that [`Assembler::rate_residual`] evaluates: of
    /// `reading.1` alone, and of both (sorted).
    rate_support: (Vec<usize>, Vec<usize>),
    /// Per element of `reading.0`, its local `M` then `C` (row-major, `nl x nl` each) at the
    /// state of the last [`Assembler::rate_jacobians`]; sized on its first call.
    rate_local: Vec<f64>,
    /// Per element, where its `M` starts in `rate_local` (elements of `reading.0`).
    rate_at: Vec<Option<usize>>,
    /// [`Assembler::rate_products`]' workspace: an element's rates, all directions.
    rate_work: Vec<f64>,
    pub residual: Residual,
    /// Generalized momenta `P = M(q) V` and transport terms `G` (`dP/dt + G = F^I`).
    pub momentum: Vec<f64>,
    pub transport: Vec<f64>,
}

impl Assembler {
    pub fn new(sys: &System) -> Assembler {
        let n = sys.len();
        let pattern = Pattern::of(n, &sys.elements);
        let mut maps = Vec::with_capacity(sys.elements.len());
        let mut indices = Vec::with_capacity(sys.elements.len());
        let mut largest = 0;
        for e in &sys.elements {
            let idx = e.indices();
            indices.push(idx.clone());
            largest = largest.max(idx.len());
            let mut m = Vec::with_capacity(idx.len() * idx.len());
            for &i in &idx {
                for &j in &idx {
                    // Present by construction of the pattern.
                    m.push(pattern.slot(i, j).unwrap_or(usize::MAX));
                }
            }
            maps.push(m);
        }
        let values = vec![0.0; pattern.nnz()];
        let rated = Self::rated(sys, &indices);
        let reading: (Vec<usize>, Vec<usize>) = (0..sys.elements.len())
            .filter(|&e| sys.elements[e].reads_rates())
            .partition(|&e| sys.elements[e].has_rates());
        let support = |elements: &[&[usize]]| {
            let mut all: Vec<usize> = elements
                .iter()
                .flat_map(|set| set.iter().flat_map(|&e| indices[e].iter().copied()))
                .collect();
            all.sort_unstable();
            all.dedup();
            all
        };
        let rate_support = (support(&[&reading.1]), support(&[&reading.0, &reading.1]));
        let mut rate_at = vec![None; sys.elements.len()];
        let mut at = 0;
        for &e in &reading.0 {
            rate_at[e] = Some(at);
            at += 2 * indices[e].len().pow(2);
        }
        Assembler {
            pattern,
            values,
            maps,
            indices,
            local: vec![0.0; largest * largest],
            local2: vec![0.0; largest * largest],
            rated,
            reading,
            rate_support,
            rate_local: Vec::new(),
            rate_at,
            rate_work: Vec::new(),
            residual: Residual::new(n),
            momentum: vec![0.0; n],
            transport: vec![0.0; n],
        }
    }

    /// The elements whose tangent depends on the rates of rotating nodes, with each node's
    /// unknowns in local positions (a node counts only with all six).
    fn rated(sys: &System, indices: &[Vec<usize>]) -> Rated {
        let mut frame_at = vec![None; sys.len()];
        for (k, &r) in sys.rotations.iter().enumerate() {
            frame_at[r] = Some(k);
        }
        let mut out = Vec::new();
        for (e, (el, idx)) in sys.elements.iter().zip(indices).enumerate() {
            if !el.has_rates() {
                continue;
            }
            let local = |g: usize| idx.iter().position(|&i| i == g);
            let nodes: Vec<(usize, [usize; 6])> = idx
                .iter()
                .filter_map(|&i| frame_at[i])
                .filter_map(|k| {
                    let (t, r) = (sys.translations[k], sys.rotations[k]);
                    let at = [t, t + 1, t + 2, r, r + 1, r + 2].map(local);
                    at.iter()
                        .all(Option::is_some)
                        .then(|| (k, at.map(|x| x.unwrap_or(0))))
                })
                .collect();
            if !nodes.is_empty() {
                out.push((e, nodes));
            }
        }
        out
    }

    /// Adds `M E_a[k] + C E_v[k]` over the columns of every frame `k`, where `M` and
    /// `C` are the elements' derivatives with respect to the accelerations and velocities
    /// (inertial components; `C` with the damping weighted by `force_weight`), and `E_a[k]`,
    /// `E_v[k]` (row-major 6x6 over the node's translation then rotation unknowns) say how the
    /// node's rates move beyond the scalar coefficients of [`Assembler::tangent`].
    pub fn add_rate_columns(
        &mut self,
        sys: &System,
        st: &State,
        aug: Augment,
        force_weight: f64,
        maps: &[([f64; 36], [f64; 36])],
        frames_only: bool,
    ) {
        self.rate_columns(sys, (st, aug, force_weight), maps, frames_only, false);
    }

    /// [`Assembler::add_rate_columns`] with the `M` and `C` of the last
    /// [`Assembler::rate_jacobians`] (its state and penalty, unit force weight) where it holds
    /// them, instead of evaluating them again.
    pub fn add_kept_rate_columns(
        &mut self,
        sys: &System,
        st: &State,
        aug: Augment,
        maps: &[([f64; 36], [f64; 36])],
        frames_only: bool,
    ) {
        self.rate_columns(sys, (st, aug, 1.0), maps, frames_only, true);
    }

    fn rate_columns(
        &mut self,
        sys: &System,
        (st, aug, w): (&State, Augment, f64),
        maps: &[([f64; 36], [f64; 36])],
        frames_only: bool,
        kept: bool,
    ) {
        let take = |k: usize| !frames_only || sys.is_frame(k);
        for (e, nodes) in &self.rated {
            if !nodes.iter().any(|&(k, _)| take(k)) {
                continue;
            }
            let (el, map) = (&sys.elements[*e], &self.maps[*e]);
            let nl2 = map.len();
            let nl = self.indices[*e].len();
            let held = self.rate_at[*e].filter(|&o| kept && o + 2 * nl2 <= self.rate_local.len());
            let (m, c) = match held {
                Some(o) => self.rate_local[o..o + 2 * nl2].split_at(nl2),
                None => {
                    let (m, c) = (&mut self.local[..nl2], &mut self.local2[..nl2]);
                    el.rate_jacobians(st, aug, w, m, c);
                    (&self.local[..nl2], &self.local2[..nl2])
                }
            };
            for (k, at) in nodes.iter().filter(|&&(k, _)| take(k)) {
                let (ev, ea) = &maps[*k];
                for i in 0..nl {
                    let (m, c) = (&m[i * nl..], &c[i * nl..]);
                    for b in 0..6 {
                        let mut sum = 0.0;
                        for (a, &la) in at.iter().enumerate() {
                            sum += m[la] * ea[a * 6 + b] + c[la] * ev[a * 6 + b];
                        }
                        if let Some(x) = self.values.get_mut(map[i * nl + at[b]]) {
                            *x += sum;
                        }
                    }
                }
            }
        }
    }

    /// Evaluates the residual parts at a state.
    pub fn residual(&mut self, sys: &System, st: &State, aug: Augment) {
        self.residual.clear();
        for e in &sys.elements {
            e.residual(st, aug, &mut self.residual);
        }
    }

    /// The residual parts of the elements that read the rates (`all`), or of those whose
    /// derivatives are not in [`Assembler::rate_jacobians`] (joints with rate rows, their rate
    /// rows alone: [`Element::rate_residual`]): its difference between two states of the
    /// same positions is the whole residual's, or the rest of it. Only the rows of
    /// [`Assembler::rate_support`] are written (the others hold whatever they held).
    pub fn rate_residual(&mut self, sys: &System, st: &State, aug: Augment, all: bool) {
        let r = &mut self.residual;
        let support = if all {
            &self.rate_support.1
        } else {
            &self.rate_support.0
        };
        for &i in support {
            (r.inertia[i], r.force[i], r.constraint[i]) = (0.0, 0.0, 0.0);
        }
        let first: &[usize] = if all { &self.reading.0 } else { &[] };
        for &e in first.iter().chain(&self.reading.1) {
            sys.elements[e].rate_residual(st, aug, &mut self.residual);
        }
    }

    /// The unknowns of the elements [`Assembler::rate_residual`] evaluates: the rows it
    /// writes, and the rates it reads.
    pub fn rate_support(&self, all: bool) -> &[usize] {
        if all {
            &self.rate_support.1
        } else {
            &self.rate_support.0
        }
    }

    /// Whether [`Assembler::rate_residual`] evaluates some element.
    pub fn has_rate_residual(&self, all: bool) -> bool {
        !self.reading.1.is_empty() || (all && !self.reading.0.is_empty())
    }

    /// The residual's derivatives with respect to the accelerations (`M`) and the velocities
    /// (`C`) at a state, kept per element with inertia or damping for
    /// [`Assembler::rate_products`] (their tangents' `mass` and `velocity` parts, as
    /// [`Assembler::add_rate_columns`] takes them).
    pub fn rate_jacobians(&mut self, sys: &System, st: &State, aug: Augment) {
        let size: usize = (self.reading.0.iter())
            .map(|&e| 2 * self.indices[e].len().pow(2))
            .sum();
        if self.rate_local.len() != size {
            self.rate_local.resize(size, 0.0);
        }
        let mut at = 0;
        for &e in &self.reading.0 {
            let nl2 = self.indices[e].len().pow(2);
            let (m, rest) = self.rate_local[at..at + 2 * nl2].split_at_mut(nl2);
            sys.elements[e].rate_jacobians(st, aug, 1.0, m, rest);
            at += 2 * nl2;
        }
    }

    /// `out += M da + C dv` with the derivatives of the last [`Assembler::rate_jacobians`],
    /// for `count` directions at once (`dv`, `da`, `out` column-major `n x count`): the
    /// residual's change along a change of the rates alone (velocities and accelerations as
    /// the state holds them: rotations' entries are angular velocities and accelerations),
    /// each element's derivatives read once for all the directions.
    pub fn rate_products(&mut self, dv: &[f64], da: &[f64], count: usize, out: &mut [f64]) {
        let n = out.len() / count.max(1);
        let widest = (self.reading.0.iter())
            .map(|&e| self.indices[e].len())
            .max()
            .unwrap_or(0);
        if self.rate_work.len() < (2 * widest + 1) * count {
            self.rate_work.resize((2 * widest + 1) * count, 0.0);
        }
        let mut at = 0;
        for &e in &self.reading.0 {
            let idx = &self.indices[e];
            let nl = idx.len();
            let (m, c) = self.rate_local[at..at + 2 * nl * nl].split_at(nl * nl);
            at += 2 * nl * nl;
            // The element's rates, row j holding every direction's.
            let (la, rest) = self.rate_work.split_at_mut(nl * count);
            let (lv, rest) = rest.split_at_mut(nl * count);
            let sum = &mut rest[..count];
            for (j, &gj) in idx.iter().enumerate() {
                for k in 0..count {
                    (la[j * count + k], lv[j * count + k]) = if gj < n {
                        (da[k * n + gj], dv[k * n + gj])
                    } else {
                        (0.0, 0.0)
                    };
                }
            }
            for (i, &gi) in idx.iter().enumerate().filter(|&(_, &gi)| gi < n) {
                sum.fill(0.0);
                for j in 0..nl {
                    let (a, b) = (m[i * nl + j], c[i * nl + j]);
                    if a == 0.0 && b == 0.0 {
                        continue;
                    }
                    let (xa, xv) = (
                        &la[j * count..(j + 1) * count],
                        &lv[j * count..(j + 1) * count],
                    );
                    for ((s, x), y) in sum.iter_mut().zip(xa).zip(xv) {
                        *s += a * x + b * y;
                    }
                }
                for (k, s) in sum.iter().enumerate() {
                    out[k * n + gi] += s;
                }
            }
        }
    }

    /// Evaluates the generalized momenta and transport terms at a state.
    pub fn momentum(&mut self, sys: &System, st: &State) {
        self.momentum.iter_mut().for_each(|x| *x = 0.0);
        self.transport.iter_mut().for_each(|x| *x = 0.0);
        for e in &sys.elements {
            e.momentum(st, &mut self.momentum, &mut self.transport);
        }
    }

    /// Evaluates the joints' residual parts alone into `out` (cleared first).
    pub fn joint_residual(&self, sys: &System, st: &State, aug: Augment, out: &mut Residual) {
        out.clear();
        for e in &sys.elements {
            if let Element::Joint(j) = e {
                j.residual(st, aug, out);
            }
        }
    }

    /// Evaluates a constraint rate into `residual.constraint`.
    pub fn constraint_rate(&mut self, sys: &System, st: &State, rate: Rate) {
        self.residual.constraint.iter_mut().for_each(|x| *x = 0.0);
        for e in &sys.elements {
            e.constraint_rate(st, rate, &mut self.residual.constraint);
        }
    }

    /// Assembles the iteration matrix into `values`.
    pub fn tangent(&mut self, sys: &System, st: &State, aug: Augment, c: TangentCoeffs) {
        self.values.iter_mut().for_each(|x| *x = 0.0);
        for (e, map) in sys.elements.iter().zip(&self.maps) {
            let nl2 = map.len();
            e.tangent(st, aug, c, &mut self.local[..nl2]);
            for (slot, v) in map.iter().zip(&self.local[..nl2]) {
                if let Some(x) = self.values.get_mut(*slot) {
                    *x += v;
                }
            }
        }
    }

    /// [`Assembler::residual`] and [`Assembler::tangent`] at one state in one pass over the
    /// elements (the same values: each element adds its parts in the same order).
    pub fn residual_and_tangent(
        &mut self,
        sys: &System,
        st: &State,
        aug: Augment,
        c: TangentCoeffs,
    ) {
        self.residual.clear();
        self.values.iter_mut().for_each(|x| *x = 0.0);
        for (e, map) in sys.elements.iter().zip(&self.maps) {
            let nl2 = map.len();
            let k = &mut self.local[..nl2];
            e.residual_and_tangent(st, aug, c, &mut self.residual, k);
            for (slot, v) in map.iter().zip(&self.local[..nl2]) {
                if let Some(x) = self.values.get_mut(*slot) {
                    *x += v;
                }
            }
        }
    }

    /// An iteration matrix over two configurations (time finite elements, THEORY §8.1): every
    /// element at `mid` with coefficients `c`, except the joints' position-level constraint rows
    /// and their penalty, which come from `end` with unit position weight (for a scheme that
    /// enforces the constraints at `end`; `aug_end` carries the penalty, `end.lambda` must be
    /// zero and `aug_mid.p` zero).
    pub fn tangent_split(
        &mut self,
        sys: &System,
        mid: &State,
        end: &State,
        aug_mid: Augment,
        aug_end: Augment,
        c: TangentCoeffs,
    ) {
        self.values.iter_mut().for_each(|x| *x = 0.0);
        let at_end = TangentCoeffs {
            mass: 0.0,
            velocity: 0.0,
            position: 1.0,
            force_weight: c.force_weight,
        };
        for ((e, map), idx) in sys.elements.iter().zip(&self.maps).zip(&self.indices) {
            let nl2 = map.len();
            e.tangent(mid, aug_mid, c, &mut self.local[..nl2]);
            if let Element::Joint(_) = e {
                e.tangent(end, aug_end, at_end, &mut self.local2[..nl2]);
                let nl = idx.len();
                for (li, &gi) in idx.iter().enumerate() {
                    let row = li * nl..(li + 1) * nl;
                    match sys.unknowns[gi] {
                        UnknownKind::Multiplier => {
                            self.local[row.clone()].copy_from_slice(&self.local2[row]);
                        }
                        UnknownKind::RateMultiplier => {}
                        _ => {
                            for (lj, &gj) in idx.iter().enumerate() {
                                if !sys.unknowns[gj].is_multiplier() {
                                    self.local[li * nl + lj] += self.local2[li * nl + lj];
                                }
                            }
                        }
                    }
                }
            }
            for (slot, v) in map.iter().zip(&self.local[..nl2]) {
                if let Some(x) = self.values.get_mut(*slot) {
                    *x += v;
                }
            }
        }
    }
}
