//! Assembly into a sparse pattern fixed once.
//!
//! Invariant: the compressed-column pattern and every element's scatter map are computed at
//! setup; assembling a Newton matrix writes values in place and allocates nothing.

use super::{Augment, Element, Rate, Residual, State, System, TangentCoeffs};

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

/// Assembles residuals and the iteration matrix of a [`System`].
pub struct Assembler {
    pub pattern: Pattern,
    /// Values of the iteration matrix, in pattern order.
    pub values: Vec<f64>,
    /// Per element: for local entry `i * nl + j` (row-major), the value slot.
    maps: Vec<Vec<usize>>,
    local: Vec<f64>,
    pub residual: Residual,
}

impl Assembler {
    pub fn new(sys: &System) -> Assembler {
        let n = sys.len();
        let pattern = Pattern::of(n, &sys.elements);
        let mut maps = Vec::with_capacity(sys.elements.len());
        let mut largest = 0;
        for e in &sys.elements {
            let idx = e.indices();
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
        Assembler {
            pattern,
            values,
            maps,
            local: vec![0.0; largest * largest],
            residual: Residual::new(n),
        }
    }

    /// Evaluates the residual parts at a state.
    pub fn residual(&mut self, sys: &System, st: &State, aug: Augment) {
        self.residual.clear();
        for e in &sys.elements {
            e.residual(st, aug, &mut self.residual);
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
}
