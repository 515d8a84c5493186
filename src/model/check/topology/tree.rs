//! The dependencies of a large loop block without a dense factorization of it.
//!
//! A spanning tree's joints are independent: each locks its child node's motion relative to
//! its parent with a block of full row rank (`D_e`, its rows on the child's columns), and the
//! tree orders them triangularly. So the block's dependencies are those of the chords (the
//! joints off the tree) on the motions the tree allows, `C P`: a column of `P` per free motion
//! of a tree joint (the null space of `D_e`) carried rigidly by the subtree beyond it, and
//! the rigid motions of each root that is not the ground. `C P` has a row per chord equation
//! and a column per degree of freedom of the tree, so its rank costs time linear in the
//! block for a few chords. A null vector `z` of `(C P)^T` is the chords' part of a dependency
//! `y`; the tree joints' part follows from the leaves in, `y_e^T D_e = -(the other assigned
//! rows on the child's columns)`, which names every joint that takes part.
//!
//! Contract: reads the block's rows; must not change the model.

use super::*;
use nalgebra::DVector;
use std::collections::{HashMap, HashSet, VecDeque};

/// A free motion of node `at` (in its own columns, rotations scaled as the rows are), carried
/// rigidly by the subtree of `at`.
struct Motion {
    at: usize,
    g: DVector<f64>,
}

/// A block's spanning forest: each node's parent and the joint to it, the breadth-first
/// order, the roots, and the subtrees as intervals `tin..tout` of a depth-first order.
struct Tree<'a> {
    model: &'a Model,
    r: &'a Rows<'a>,
    block: &'a [usize],
    rows_of: &'a dyn Fn(usize) -> std::ops::Range<usize>,
    parent: HashMap<usize, (usize, usize)>,
    order: Vec<usize>,
    roots: Vec<usize>,
    on_tree: Vec<bool>,
    span: HashMap<usize, (usize, usize)>,
}

impl<'a> Tree<'a> {
    fn new(
        model: &'a Model,
        r: &'a Rows<'a>,
        block: &'a [usize],
        rows_of: &'a dyn Fn(usize) -> std::ops::Range<usize>,
    ) -> Tree<'a> {
        let ground = r.cols.nodes.len();
        let mut adj: HashMap<usize, Vec<(usize, usize)>> = HashMap::new();
        for (b, &j) in block.iter().enumerate() {
            let v = vertices(model, r.cols, &model.joints[j]);
            if let [a, c] = v[..] {
                adj.entry(a).or_default().push((c, b));
                adj.entry(c).or_default().push((a, b));
            }
            for &x in &v {
                adj.entry(x).or_default();
            }
        }
        // Breadth-first, from the ground first when the block holds it.
        let mut all: Vec<usize> = adj.keys().copied().collect();
        all.sort_unstable_by_key(|&v| (v != ground, v));
        let (mut parent, mut seen) = (HashMap::new(), HashSet::new());
        let (mut order, mut roots, mut on_tree) =
            (Vec::new(), Vec::new(), vec![false; block.len()]);
        for &root in &all {
            if !seen.insert(root) {
                continue;
            }
            roots.push(root);
            let mut queue = VecDeque::from([root]);
            while let Some(u) = queue.pop_front() {
                order.push(u);
                for &(w, b) in &adj[&u] {
                    if w != ground && seen.insert(w) {
                        parent.insert(w, (u, b));
                        on_tree[b] = true;
                        queue.push_back(w);
                    }
                }
            }
        }
        let mut children: HashMap<usize, Vec<usize>> = HashMap::new();
        for &w in &order {
            if let Some(&(u, _)) = parent.get(&w) {
                children.entry(u).or_default().push(w);
            }
        }
        let (mut span, mut time) = (HashMap::new(), 0usize);
        for &root in &roots {
            let mut stack = vec![(root, false)];
            while let Some((v, done)) = stack.pop() {
                if done {
                    span.entry(v)
                        .and_modify(|s: &mut (usize, usize)| s.1 = time);
                    continue;
                }
                span.insert(v, (time, time));
                time += 1;
                stack.push((v, true));
                for &w in children.get(&v).map_or(&[][..], |c| &c[..]) {
                    stack.push((w, false));
                }
            }
        }
        Tree {
            model,
            r,
            block,
            rows_of,
            parent,
            order,
            roots,
            on_tree,
            span,
        }
    }

    fn inside(&self, x: usize, c: usize) -> bool {
        let (a, b) = (self.span[&c], self.span[&x]);
        a.0 <= b.0 && b.0 < a.1
    }

    fn node_of(&self, c: usize) -> usize {
        self.r.cols.start.partition_point(|&s| s <= c) - 1
    }

    /// Row `i`'s entries on node `k`.
    fn on(&self, i: usize, k: usize) -> DVector<f64> {
        let cols = self.r.cols;
        let mut v = DVector::zeros(cols.width(k));
        for &(c, x) in &self.r.rows[i] {
            if self.node_of(c) == k {
                v[c - cols.start[k]] += x;
            }
        }
        v
    }

    /// The rows of block joint `b` on node `k`.
    fn d_of(&self, b: usize, k: usize) -> DMatrix<f64> {
        let rows: Vec<usize> = (self.rows_of)(self.block[b]).collect();
        let on: Vec<DVector<f64>> = rows.iter().map(|&i| self.on(i, k)).collect();
        DMatrix::from_fn(rows.len(), self.r.cols.width(k), |a, q| on[a][q])
    }

    fn touched(&self, i: usize) -> Vec<usize> {
        let mut t: Vec<usize> = self.r.rows[i]
            .iter()
            .map(|&(c, _)| self.node_of(c))
            .collect();
        t.sort_unstable();
        t.dedup();
        t
    }

    /// The roots' rigid motions (but the ground's) and each tree joint's free motions.
    fn motions(&self) -> Vec<Motion> {
        let (cols, ground) = (self.r.cols, self.r.cols.nodes.len());
        let mut motions = Vec::new();
        for &root in self.roots.iter().filter(|&&v| v != ground) {
            for q in 0..cols.width(root) {
                let mut g = DVector::zeros(cols.width(root));
                g[q] = 1.0;
                motions.push(Motion { at: root, g });
            }
        }
        for &c in &self.order {
            let Some(&(_, b)) = self.parent.get(&c) else {
                continue;
            };
            let d = self.d_of(b, c);
            let eig = SymmetricEigen::new(d.transpose() * &d);
            let mut idx: Vec<usize> = (0..d.ncols()).collect();
            idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
            for &q in &idx[..d.ncols().saturating_sub(d.nrows())] {
                let g = eig.eigenvectors.column(q).into_owned();
                motions.push(Motion { at: c, g });
            }
        }
        motions
    }

    /// How a free motion moves node `x` of its subtree: rigidly.
    fn carried(&self, m: &Motion, x: usize) -> DVector<f64> {
        let cols = self.r.cols;
        let th = if cols.rotates[m.at] {
            [m.g[3], m.g[4], m.g[5]]
        } else {
            [0.0; 3]
        };
        let at = |k: usize| node_position(self.model, cols.nodes[k]);
        let turn = cross(th, sub(at(x), at(m.at)));
        let mut v = DVector::zeros(cols.width(x));
        for i in 0..3 {
            v[i] = m.g[i] + turn[i] / self.r.scale;
            if cols.rotates[x] {
                v[3 + i] = th[i];
            }
        }
        v
    }

    /// The chords' rows, and `C P`: each on each free motion.
    fn chords(&self, motions: &[Motion]) -> (Vec<usize>, DMatrix<f64>) {
        let rows: Vec<usize> = (0..self.block.len())
            .filter(|&b| !self.on_tree[b])
            .flat_map(|b| (self.rows_of)(self.block[b]))
            .collect();
        let mut cp = DMatrix::<f64>::zeros(rows.len(), motions.len());
        for (a, &i) in rows.iter().enumerate() {
            for x in self.touched(i) {
                let row = self.on(i, x);
                for (q, m) in motions.iter().enumerate() {
                    if self.inside(x, m.at) {
                        cp[(a, q)] += row.dot(&self.carried(m, x));
                    }
                }
            }
        }
        (rows, cp)
    }

    /// The whole dependency from its chords' part `y`, tree joints from the leaves in, as
    /// (row, coefficient) pairs of unit norm.
    fn complete(
        &self,
        mut y: HashMap<usize, f64>,
        touching: &HashMap<usize, Vec<usize>>,
    ) -> Vec<(usize, f64)> {
        for &c in self.order.iter().rev() {
            let Some(&(_, b)) = self.parent.get(&c) else {
                continue;
            };
            let own: Vec<usize> = (self.rows_of)(self.block[b]).collect();
            let mut rhs = DVector::zeros(self.r.cols.width(c));
            for &i in touching.get(&c).map_or(&[][..], |t| &t[..]) {
                if let (false, Some(&yi)) = (own.contains(&i), y.get(&i)) {
                    rhs += self.on(i, c) * yi;
                }
            }
            let d = self.d_of(b, c);
            let ye = (&d * d.transpose())
                .lu()
                .solve(&(&d * rhs))
                .unwrap_or_else(|| DVector::zeros(own.len()));
            for (k, &i) in own.iter().enumerate() {
                y.insert(i, -ye[k]);
            }
        }
        let norm = y.values().map(|v| v * v).sum::<f64>().sqrt().max(1e-300);
        let mut dep: Vec<(usize, f64)> = y.into_iter().map(|(i, v)| (i, v / norm)).collect();
        dep.sort_unstable_by_key(|&(i, _)| i);
        dep
    }
}

/// The block's dependencies, each as (row, coefficient) pairs of unit norm.
pub(super) fn dependencies(
    model: &Model,
    r: &Rows,
    block: &[usize],
    rows_of: &dyn Fn(usize) -> std::ops::Range<usize>,
) -> Vec<Vec<(usize, f64)>> {
    let tree = Tree::new(model, r, block, rows_of);
    let motions = tree.motions();
    let (chord_rows, cp) = tree.chords(&motions);
    let eig = SymmetricEigen::new(&cp * cp.transpose());
    let top = eig.eigenvalues.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let size = chord_rows
        .iter()
        .map(|&i| r.rows[i].iter().map(|(_, v)| v * v).sum::<f64>())
        .fold(0.0f64, f64::max);
    let tol = 1e-10 * top.max(size).max(1e-30) * chord_rows.len() as f64;
    let mut touching: HashMap<usize, Vec<usize>> = HashMap::new();
    for &j in block {
        for i in rows_of(j) {
            for x in tree.touched(i) {
                touching.entry(x).or_default().push(i);
            }
        }
    }
    (0..chord_rows.len())
        .filter(|&c| eig.eigenvalues[c].abs() <= tol)
        .map(|z| {
            let y = chord_rows
                .iter()
                .enumerate()
                .map(|(a, &i)| (i, eig.eigenvectors[(a, z)]));
            tree.complete(y.collect(), &touching)
        })
        .collect()
}
