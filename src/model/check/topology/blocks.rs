//! Where the rank checks need numbers: the graph of nodes (ground one vertex) and joints.
//!
//! A joint that is a bridge of that graph (its removal splits it) never takes part in a
//! dependency of the constraint equations. Proof: let `B` be the side without the ground. A
//! rigid virtual motion of all of `B` leaves every joint inside `B` satisfied and no other
//! joint touches `B`, so a combination `y` of rows with `y^T J = 0` gives `y_e^T J_e d = 0`
//! for the bridge `e` and every rigid motion `d` of `B`; and `J_e d` covers every value as `d`
//! ranges over `B`'s six rigid motions (a joint's own locked directions are independent), so
//! `y_e = 0`. The other joints fall into blocks whose columns are disjoint (the union of
//! their nodes), so the constraint Jacobian's rank is the bridges' rows plus each block's
//! rank: a tree of any size costs no factorization, a loop one dense check of its own size.
//!
//! Contract: graph algorithms on vertex and edge lists; must not know the model.

/// Disjoint sets with path halving.
pub struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    pub fn new(n: usize) -> UnionFind {
        UnionFind {
            parent: (0..n).collect(),
        }
    }

    pub fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    pub fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.parent[a] = b;
        }
    }
}

/// Which of the `edges` (vertex pairs, parallel edges and loops allowed) are bridges, by one
/// depth-first search with low links, on an explicit stack (no recursion: a chain of any
/// length is one deep path).
pub fn bridges(nv: usize, edges: &[(usize, usize)]) -> Vec<bool> {
    let mut start = vec![0usize; nv + 1];
    for &(a, b) in edges {
        start[a + 1] += 1;
        start[b + 1] += 1;
    }
    for v in 0..nv {
        start[v + 1] += start[v];
    }
    let mut fill = start.clone();
    let mut adj = vec![(0usize, 0usize); start[nv]];
    for (e, &(a, b)) in edges.iter().enumerate() {
        adj[fill[a]] = (b, e);
        fill[a] += 1;
        adj[fill[b]] = (a, e);
        fill[b] += 1;
    }
    const NONE: usize = usize::MAX;
    let (mut disc, mut low) = (vec![NONE; nv], vec![0usize; nv]);
    let mut bridge = vec![false; edges.len()];
    let mut time = 0;
    // (vertex, the edge it was reached by, the next adjacency to look at)
    let mut stack: Vec<(usize, usize, usize)> = Vec::new();
    for root in 0..nv {
        if disc[root] != NONE {
            continue;
        }
        disc[root] = time;
        low[root] = time;
        time += 1;
        stack.push((root, NONE, start[root]));
        while let Some(top) = stack.last_mut() {
            let (v, via) = (top.0, top.1);
            if top.2 < start[v + 1] {
                let (w, e) = adj[top.2];
                top.2 += 1;
                if e == via {
                    continue;
                }
                if disc[w] == NONE {
                    disc[w] = time;
                    low[w] = time;
                    time += 1;
                    stack.push((w, e, start[w]));
                } else {
                    low[v] = low[v].min(disc[w]);
                }
            } else {
                stack.pop();
                if let Some(&(u, _, _)) = stack.last() {
                    low[u] = low[u].min(low[v]);
                    if low[v] > disc[u] {
                        bridge[via] = true;
                    }
                }
            }
        }
    }
    bridge
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_is_all_bridges_and_a_loop_none() {
        let chain: Vec<_> = (0..5).map(|i| (i, i + 1)).collect();
        assert!(bridges(6, &chain).iter().all(|&b| b));
        let mut ring = chain.clone();
        ring.push((5, 0));
        assert!(bridges(6, &ring).iter().all(|&b| !b));
        // A loop with a tail; a doubled edge and a self-loop are never bridges.
        let g = [(0, 1), (1, 2), (2, 0), (2, 3), (3, 4), (3, 4), (4, 4)];
        assert_eq!(
            bridges(5, &g),
            [false, false, false, true, false, false, false]
        );
    }
}
