//! The elimination order and the supernodes of the pivot-free LU (THEORY §6), found once per
//! pattern.
//!
//! Columns with the same pattern (a node's 3 or 6 unknowns, a joint's multipliers) form one
//! supervariable. Supervariables are eliminated by minimum (external) degree on the explicit
//! elimination graph, and a joint's multipliers only once every unknown they couple that is
//! not itself a multiplier has been eliminated: each then meets the pivot
//! `-s^2 b A^-1 b^T != 0`, so the factorization needs no pivoting. Each supervariable is a
//! supernode: its columns share a dense diagonal block and the rows that remain coupled to it
//! when it is eliminated. Ties are broken by the first column, so the order depends on the
//! pattern alone.
//!
//! Contract: reads a symmetric pattern (with its diagonal) and which unknowns are multipliers;
//! must not know values, elements or the integrator.

use crate::runtime::Pattern;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// The order and supernodes of a pattern.
pub struct Elimination {
    /// `perm[new] = old`.
    pub perm: Vec<usize>,
    /// `first[s]..first[s + 1]`: the new columns of supernode `s`.
    pub first: Vec<usize>,
    /// The rows (new indices, increasing) below supernode `s`'s diagonal block:
    /// `rows[rows_ptr[s]..rows_ptr[s + 1]]`.
    pub rows: Vec<usize>,
    pub rows_ptr: Vec<usize>,
}

/// Supervariables: columns with the same rows and the same kind, numbered by their first
/// column; `members[v]` in increasing column order.
fn supervariables(p: &Pattern, late: &[bool]) -> (Vec<usize>, Vec<Vec<usize>>) {
    let mut of = vec![0usize; p.n];
    let mut members: Vec<Vec<usize>> = Vec::new();
    let mut seen: HashMap<(bool, &[usize]), usize> = HashMap::new();
    for j in 0..p.n {
        let key = (late[j], &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]]);
        let v = *seen.entry(key).or_insert_with(|| {
            members.push(Vec::new());
            members.len() - 1
        });
        members[v].push(j);
        of[j] = v;
    }
    (of, members)
}

/// Sorted union of `a` and `b` without `skip1` and `skip2`, into `out`.
fn merge_into(a: &[usize], b: &[usize], skip: (usize, usize), out: &mut Vec<usize>) {
    out.clear();
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let x = match (a.get(i), b.get(j)) {
            (Some(&x), Some(&y)) if x == y => {
                i += 1;
                j += 1;
                x
            }
            (Some(&x), Some(&y)) if x < y => {
                i += 1;
                x
            }
            (Some(_), Some(&y)) => {
                j += 1;
                y
            }
            (Some(&x), None) => {
                i += 1;
                x
            }
            (None, Some(&y)) => {
                j += 1;
                y
            }
            (None, None) => unreachable!(),
        };
        if x != skip.0 && x != skip.1 {
            out.push(x);
        }
    }
}

impl Elimination {
    /// The order of a structurally symmetric `pattern` whose unknowns flagged in `late`
    /// (multipliers) must follow the other unknowns they couple.
    pub fn of(pattern: &Pattern, late: &[bool]) -> Elimination {
        let (of, members) = supervariables(pattern, late);
        let nv = members.len();
        let weight: Vec<usize> = members.iter().map(Vec::len).collect();
        let vlate: Vec<bool> = members.iter().map(|m| late[m[0]]).collect();
        // The supervariable graph, without self loops.
        let original: Vec<Vec<usize>> = members
            .iter()
            .enumerate()
            .map(|(v, m)| {
                let j = m[0];
                let mut adj: Vec<usize> = pattern.row_idx
                    [pattern.col_ptr[j]..pattern.col_ptr[j + 1]]
                    .iter()
                    .map(|&i| of[i])
                    .filter(|&u| u != v)
                    .collect();
                adj.sort_unstable();
                adj.dedup();
                adj
            })
            .collect();
        let mut adj = original.clone();
        let mut pending: Vec<usize> = (0..nv)
            .map(|v| {
                if vlate[v] {
                    original[v].iter().filter(|&&u| !vlate[u]).count()
                } else {
                    0
                }
            })
            .collect();
        let degree_of = |adj: &[usize]| adj.iter().map(|&u| weight[u]).sum::<usize>();
        let mut degree: Vec<usize> = adj.iter().map(|a| degree_of(a)).collect();
        let mut heap = BinaryHeap::new();
        for v in 0..nv {
            if pending[v] == 0 {
                heap.push(Reverse((degree[v], v)));
            }
        }
        let mut done = vec![false; nv];
        let mut order = Vec::with_capacity(nv);
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); nv];
        let mut scratch = Vec::new();
        while let Some(Reverse((d, v))) = heap.pop() {
            if done[v] || d != degree[v] || pending[v] != 0 {
                continue;
            }
            done[v] = true;
            order.push(v);
            let nbrs = std::mem::take(&mut adj[v]);
            for &u in &nbrs {
                merge_into(&adj[u], &nbrs, (u, v), &mut scratch);
                std::mem::swap(&mut adj[u], &mut scratch);
                degree[u] = degree_of(&adj[u]);
                if pending[u] == 0 {
                    heap.push(Reverse((degree[u], u)));
                }
            }
            if !vlate[v] {
                for &u in &original[v] {
                    if vlate[u] && !done[u] {
                        pending[u] -= 1;
                        if pending[u] == 0 {
                            heap.push(Reverse((degree[u], u)));
                        }
                    }
                }
            }
            below[v] = nbrs;
        }
        debug_assert_eq!(order.len(), nv, "every supervariable is eliminated");
        // Number the columns in elimination order; each supervariable is a supernode.
        let mut start = vec![0usize; nv];
        let (mut perm, mut first) = (Vec::with_capacity(pattern.n), Vec::with_capacity(nv + 1));
        for &v in &order {
            start[v] = perm.len();
            first.push(perm.len());
            perm.extend_from_slice(&members[v]);
        }
        first.push(perm.len());
        let (mut rows, mut rows_ptr) = (Vec::new(), vec![0]);
        for &v in &order {
            let mut next: Vec<usize> = below[v].clone();
            next.sort_unstable_by_key(|&u| start[u]);
            for u in next {
                rows.extend(start[u]..start[u] + weight[u]);
            }
            rows_ptr.push(rows.len());
        }
        Elimination {
            perm,
            first,
            rows,
            rows_ptr,
        }
    }

    pub fn supernodes(&self) -> usize {
        self.first.len() - 1
    }
}
