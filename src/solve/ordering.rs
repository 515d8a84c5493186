//! The elimination order and the supernodes of the pivot-free LU (THEORY §6), found once per
//! pattern.
//!
//! Columns with the same pattern (a node's 3 or 6 unknowns, a joint's multipliers) form one
//! supervariable. Supervariables are eliminated by minimum (external) degree on the explicit
//! elimination graph, and a joint's multipliers only once the unknowns they couple have been
//! eliminated: all of them ([`Rule::Strict`], THEORY §6: the pivot `-s^2 b A^-1 b^T != 0`),
//! or those of one side ([`Rule::OneSide`], the iteration matrix's order): a supervariable
//! with a column of its own for each of the joint's rows, not yet matched to the rows of
//! another joint eliminated through it. The pivot is then `-s^2 b_1 S_1^-1 b_1^T`, `S_1` the
//! side's block with what was eliminated before it attached (positive definite, as `A`), and
//! nonzero when the joint's rows are independent on that side, as they are for a joint of
//! relative motion between two nodes: a blade, its hinge's multipliers eliminated after it,
//! leaves the hub a 6 x 6 block, where the strict order couples every blade's multipliers
//! through the hub (the windmill: 24,743 multiply-adds a factorization against 55,355; a
//! 100-link chain 425,394 against 850,482). A joint whose rows are dependent on a side meets
//! a tiny pivot, and `linear.rs` then orders the pattern strictly. Each supervariable is a
//! supernode: its columns share a dense diagonal block and the rows that remain coupled to it
//! when it is eliminated. Ties are broken by the first column, so the order depends on the
//! pattern alone.
//!
//! Contract: reads a symmetric pattern (with its diagonal) and which unknowns are multipliers;
//! must not know values, elements or the integrator.

use crate::runtime::Pattern;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// When a joint's multipliers may be eliminated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// After every unknown they couple that is not a multiplier: the pivot `-s^2 b A^-1 b^T`
    /// is nonzero for any joint.
    Strict,
    /// After the unknowns of one side: a supervariable they couple, eliminated, with a column
    /// of its own for each of their rows not yet taken by another multiplier eliminated
    /// through it. The pivot is `-s^2 b_1 A_1^-1 b_1^T`, nonzero when the joint's rows are
    /// independent on that side (so for every joint of relative motion); a blade then leaves
    /// the hub a 6 x 6 block instead of coupling every blade's multipliers through it.
    OneSide,
}

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
    /// (multipliers) must follow the other unknowns they couple ([`Rule::Strict`]), or those
    /// of one side ([`Rule::OneSide`]).
    pub fn of(pattern: &Pattern, late: &[bool], rule: Rule) -> Elimination {
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
        // Of each eliminated supervariable that is not a multiplier, the columns not yet
        // matched to a multiplier row eliminated through it (Rule::OneSide).
        let mut spare = vec![0usize; nv];
        let mut order = Vec::with_capacity(nv);
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); nv];
        let mut scratch = Vec::new();
        // The eliminated side a multiplier may follow: a neighbour with spare columns for
        // every row of it.
        let side = |v: usize, done: &[bool], spare: &[usize]| {
            original[v]
                .iter()
                .copied()
                .filter(|&u| done[u] && !vlate[u] && spare[u] >= weight[v])
                .max_by_key(|&u| (spare[u], Reverse(u)))
        };
        while let Some(Reverse((d, v))) = heap.pop() {
            if done[v] || d != degree[v] {
                continue;
            }
            if vlate[v] && rule == Rule::OneSide {
                // Rows matched to the columns of a side; a multiplier whose every unknown
                // has been eliminated takes what the sides have left.
                match side(v, &done, &spare) {
                    Some(u) => spare[u] -= weight[v],
                    None if pending[v] == 0 => {
                        let mut rows = weight[v];
                        for &u in original[v].iter().filter(|&&u| !vlate[u]) {
                            let take = rows.min(spare[u]);
                            (spare[u], rows) = (spare[u] - take, rows - take);
                        }
                    }
                    None => continue,
                }
            } else if pending[v] != 0 {
                continue;
            }
            done[v] = true;
            if !vlate[v] {
                spare[v] = weight[v];
            }
            order.push(v);
            let nbrs = std::mem::take(&mut adj[v]);
            for &u in &nbrs {
                merge_into(&adj[u], &nbrs, (u, v), &mut scratch);
                std::mem::swap(&mut adj[u], &mut scratch);
                degree[u] = degree_of(&adj[u]);
                if pending[u] == 0 || (rule == Rule::OneSide && vlate[u]) {
                    heap.push(Reverse((degree[u], u)));
                }
            }
            if !vlate[v] {
                for &u in &original[v] {
                    if vlate[u] && !done[u] {
                        pending[u] -= 1;
                        if pending[u] == 0 || rule == Rule::OneSide {
                            heap.push(Reverse((degree[u], u)));
                        }
                    }
                }
            }
            below[v] = nbrs;
        }
        debug_assert_eq!(order.len(), nv, "every supervariable is eliminated");
        Self::numbered(pattern.n, &order, &members, &below)
    }

    /// Numbers the columns in elimination `order`; each supervariable is a supernode, its
    /// rows below those of the supervariables in `below[v]`.
    fn numbered(
        n: usize,
        order: &[usize],
        members: &[Vec<usize>],
        below: &[Vec<usize>],
    ) -> Elimination {
        let nv = members.len();
        let mut start = vec![0usize; nv];
        let (mut perm, mut first) = (Vec::with_capacity(n), Vec::with_capacity(nv + 1));
        for &v in order {
            start[v] = perm.len();
            first.push(perm.len());
            perm.extend_from_slice(&members[v]);
        }
        first.push(perm.len());
        let (mut rows, mut rows_ptr) = (Vec::new(), vec![0]);
        for &v in order {
            let mut next: Vec<usize> = below[v].clone();
            next.sort_unstable_by_key(|&u| start[u]);
            for u in next {
                rows.extend(start[u]..start[u] + members[u].len());
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
