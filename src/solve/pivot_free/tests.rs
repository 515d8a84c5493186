//! The pivot-free LU's tests: against faer's pivoting LU, the orders' rules, tiny pivots.
use super::*;
use crate::solve::linear::{LinearError, SparseLu};

/// A matrix of the iteration matrix's shape: `nodes` nodes of `w` unknowns on a chain
/// and a star, joints of `k` multipliers between neighbours, `[A + p B^T B, s B^T; s B, 0]`
/// with `A` diagonally dominant and unsymmetric.
fn augmented(nodes: usize, w: usize, k: usize, seed: u64) -> (Pattern, Vec<bool>, Vec<f64>) {
    let mut state = seed;
    let mut rnd = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let mut pairs: Vec<(usize, usize)> = (1..nodes).map(|i| (i - 1, i)).collect();
    pairs.extend((2..nodes).step_by(3).map(|i| (0, i)));
    // Multipliers first in the numbering, so the order must move them.
    let nm = pairs.len() * k;
    let n = nm + nodes * w;
    let q = |node: usize, a: usize| nm + node * w + a;
    let mut dense = vec![0.0; n * n];
    let mut coupled = vec![false; n * n];
    let mut couple = |i: usize, j: usize, v: f64, d: &mut Vec<f64>| {
        d[i + j * n] += v;
        coupled[i + j * n] = true;
        coupled[j + i * n] = true;
    };
    for node in 0..nodes {
        for a in 0..w {
            for b in 0..w {
                let v = if a == b { 10.0 } else { rnd() };
                couple(q(node, a), q(node, b), v, &mut dense);
            }
        }
    }
    let (s, p) = (3.0, 3.0);
    for (c, &(na, nb)) in pairs.iter().enumerate() {
        let idx: Vec<usize> = (0..w)
            .map(|a| q(na, a))
            .chain((0..w).map(|a| q(nb, a)))
            .collect();
        for r in 0..k {
            let b: Vec<f64> = idx.iter().map(|_| rnd()).collect();
            let m = c * k + r;
            for (x, &i) in idx.iter().enumerate() {
                couple(m, i, s * b[x], &mut dense);
                couple(i, m, s * b[x], &mut dense);
                for (y, &j) in idx.iter().enumerate() {
                    couple(i, j, p * b[x] * b[y], &mut dense);
                }
            }
            for r2 in 0..k {
                couple(m, c * k + r2, 0.0, &mut dense);
            }
        }
    }
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            if coupled[i + j * n] || i == j {
                row_idx.push(i);
                values.push(dense[i + j * n]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    let late = (0..n).map(|i| i < nm).collect();
    (
        Pattern {
            n,
            col_ptr,
            row_idx,
        },
        late,
        values,
    )
}

fn solve_both(nodes: usize, w: usize, k: usize, seed: u64, rule: Rule) -> (f64, PivotFree) {
    let (pattern, late, values) = augmented(nodes, w, k, seed);
    let mut fast = PivotFree::new(&pattern, &late, rule);
    let mut slow = SparseLu::new(&pattern).expect("faer");
    let rhs: Vec<f64> = (0..pattern.n).map(|i| (i as f64 * 0.37).sin()).collect();
    let (mut x, mut y) = (rhs.clone(), rhs);
    // Twice, so that refactoring into the same storage is checked too.
    for scale in [1.0, 2.0] {
        let v: Vec<f64> = values.iter().map(|v| v * scale).collect();
        fast.factor(&v)
            .unwrap_or_else(|e| panic!("{nodes} {w} {k} {seed} {rule:?}: {e:?}"));
        slow.factor(&v).expect("faer factors");
    }
    fast.solve(&mut x);
    slow.solve(&mut y).expect("faer solves");
    let size = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let err = x
        .iter()
        .zip(&y)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    (err / size, fast)
}

#[test]
fn agrees_with_pivoting_lu_on_augmented_lagrangian_matrices() {
    // Rigid frames with 5-multiplier joints, point masses with 1-multiplier joints.
    for (nodes, w, k) in [(2, 6, 5), (7, 6, 5), (30, 6, 3), (12, 3, 1), (50, 3, 2)] {
        for (seed, rule) in (1..4).flat_map(|s| [(s, Rule::Strict), (s, Rule::OneSide)]) {
            let (err, _) = solve_both(nodes, w, k, seed, rule);
            assert!(
                err < 1e-12,
                "{nodes} nodes of {w}, {k} multipliers, {rule:?}: {err:e}"
            );
        }
    }
}

/// Several right-hand sides at once give each one's substitution, to round-off.
#[test]
fn many_right_hand_sides_are_each_ones_substitution() {
    for (nodes, w, k) in [(7, 6, 5), (30, 6, 3), (12, 3, 1)] {
        let (_, mut fast) = solve_both(nodes, w, k, 2, Rule::Strict);
        let n = fast.perm.len();
        let count = 5;
        let rhs: Vec<f64> = (0..n * count).map(|i| (i as f64 * 0.71).cos()).collect();
        let mut many = rhs.clone();
        fast.substitute_many(&mut many, count);
        for c in 0..count {
            let mut one = rhs[c * n..(c + 1) * n].to_vec();
            fast.substitute(&mut one);
            let size = one.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in one.iter().zip(&many[c * n..(c + 1) * n]) {
                assert!((a - b).abs() <= 1e-13 * size, "{nodes} nodes: {a} vs {b}");
            }
        }
    }
}

#[test]
fn multipliers_follow_what_they_couple_and_supernodes_are_blocks() {
    let (pattern, late, _) = augmented(10, 6, 5, 7);
    let e = Elimination::of(&pattern, &late, Rule::Strict);
    let mut at = vec![0; pattern.n];
    for (k, &o) in e.perm.iter().enumerate() {
        at[o] = k;
    }
    for j in 0..pattern.n {
        if late[j] {
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                assert!(
                    late[i] || at[i] < at[j],
                    "multiplier {j} before unknown {i}"
                );
            }
        }
    }
    // 10 nodes of 6 and 12 joints of 5 multipliers: one supernode each.
    assert_eq!(e.supernodes(), 10 + 12);
}

/// One side's unknowns suffice: each multiplier follows a node it couples, and on chains
/// with a star (25 nodes, a hub joined to 8 of them) the work falls (measured: 450,696
/// multiply-adds against 726,216 strictly, 0.62).
#[test]
fn one_side_orders_multipliers_after_a_node_of_theirs_with_less_fill() {
    let (pattern, late, _) = augmented(25, 6, 5, 7);
    let e = Elimination::of(&pattern, &late, Rule::OneSide);
    let mut at = vec![0; pattern.n];
    for (k, &o) in e.perm.iter().enumerate() {
        at[o] = k;
    }
    for m in (0..pattern.n).filter(|&m| late[m]) {
        let col = &pattern.row_idx[pattern.col_ptr[m]..pattern.col_ptr[m + 1]];
        let after = col.iter().any(|&i| !late[i] && at[i] < at[m]);
        assert!(after, "multiplier {m} before every node it couples");
    }
    let count = |rule| {
        let d = PivotFree::new(&pattern, &late, rule).describe();
        let t = d.rsplit(", ").next().unwrap_or_default().to_string();
        t.split(' ').next().and_then(|x| x.parse::<usize>().ok())
    };
    let (one, strict) = (count(Rule::OneSide), count(Rule::Strict));
    assert!(matches!((one, strict), (Some(a), Some(b)) if 4 * a < 3 * b));
}

#[test]
fn reports_a_tiny_pivot_at_its_unknown() {
    // [[0, 1], [1, 0]] with neither flagged late: the first pivot is zero.
    let pattern = Pattern {
        n: 2,
        col_ptr: vec![0, 2, 4],
        row_idx: vec![0, 1, 0, 1],
    };
    for make in [PivotFree::new, PivotFree::supernodal] {
        let mut lu = make(&pattern, &[false, false], Rule::Strict);
        assert!(lu.factor(&[0.0, 1.0, 1.0, 0.0]).is_err());
        // Flagging the second as a multiplier does not help a zero first pivot, but a
        // nonzero one factors.
        lu.factor(&[2.0, 1.0, 1.0, 0.0]).expect("pivots 2 and -0.5");
        let mut x = [3.0, 1.0];
        lu.solve(&mut x);
        assert!(
            (x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15,
            "{x:?}"
        );
    }
}

/// A joint whose rows are dependent on each side alone (`[[1, 1, 1, 1], [1, 1, 2, 2]]` on
/// nodes a and b): the order through one side meets a zero pivot, and the strict order
/// takes over, still without pivoting.
#[test]
fn a_joint_dependent_on_each_side_takes_the_strict_order() {
    // Multipliers 0-1 (a-b), 2-3 (b-c); nodes a 4-5, b 6-7, c 8-9; p = s = 1.
    let n = 10;
    let mut k = vec![0.0; n * n];
    let joints: [([usize; 4], [[f64; 4]; 2], usize); 2] = [
        (
            [4, 5, 6, 7],
            [[1.0, 1.0, 1.0, 1.0], [1.0, 1.0, 2.0, 2.0]],
            0,
        ),
        (
            [6, 7, 8, 9],
            [[1.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, -1.0]],
            2,
        ),
    ];
    for node in [4, 6, 8] {
        for (i, j, v) in [(0, 0, 10.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 10.0)] {
            k[node + i + (node + j) * n] = v;
        }
    }
    for (at, b, m) in joints {
        for r in 0..2 {
            for (x, &i) in at.iter().enumerate() {
                k[m + r + i * n] += b[r][x];
                k[i + (m + r) * n] += b[r][x];
                for (y, &j) in at.iter().enumerate() {
                    k[i + j * n] += b[r][x] * b[r][y];
                }
            }
        }
    }
    let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
    for j in 0..n {
        for i in (0..n).filter(|&i| k[i + j * n] != 0.0 || i == j) {
            row_idx.push(i);
            values.push(k[i + j * n]);
        }
        col_ptr.push(row_idx.len());
    }
    let pattern = Pattern {
        n,
        col_ptr,
        row_idx,
    };
    let late: Vec<bool> = (0..n).map(|i| i < 4).collect();
    let rhs: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
    let (mut x, mut y) = (rhs.clone(), rhs);
    for make in [PivotFree::new, PivotFree::supernodal] {
        let one_side = make(&pattern, &late, Rule::OneSide).factor(&values);
        assert_eq!(one_side, Err(TinyPivot(1)));
    }
    let mut lu = SparseLu::pivot_free(&pattern, &late);
    lu.factor(&values).expect("the strict order factors it");
    lu.solve(&mut x).expect("solve");
    assert_eq!((lu.tiny_pivot(), lu.rule()), (None, Rule::Strict));
    let mut faer = SparseLu::new(&pattern).expect("symbolic");
    faer.factor(&values).expect("numeric");
    faer.solve(&mut y).expect("solve");
    let err = x
        .iter()
        .zip(&y)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(err < 1e-12, "{err:e}");
}

/// The refinement is measured on the first factorization's solves and every
/// [`CHECK_EVERY`]-th's. Where the factors grow (a pivot of 1e-9 against entries of one: `U`
/// holds -1e9), the substitution alone is off by 8.3e-8 and every solve refines, to 3.3e-16;
/// where they do not (an augmented matrix as above), the first refinement moves the solution
/// by less than [`REFINE_ABOVE`] of it, and the substitutions until the next check are as
/// close to faer's (4.2e-14 of the largest entry, refined or not).
#[test]
fn refines_where_the_factors_grow_and_only_there() -> Result<(), LinearError> {
    let pattern = Pattern {
        n: 2,
        col_ptr: vec![0, 2, 4],
        row_idx: vec![0, 1, 0, 1],
    };
    let mut lu = PivotFree::new(&pattern, &[false, false], Rule::Strict);
    let pivot = lu.factor(&[1e-9, 1.0, 1.0, 1.0]);
    assert!(pivot.is_ok(), "a pivot of 1e-9 of its column: {pivot:?}");
    // x = (1, 3).
    let rhs = [1e-9 + 3.0, 4.0];
    let err = |x: &[f64; 2]| (x[0] - 1.0).abs().max((x[1] - 3.0).abs());
    let mut alone = rhs;
    lu.substitute(&mut alone);
    assert!(err(&alone) > 2.8e-8, "substitution alone {:e}", err(&alone));
    for k in 0..2 * CHECK_EVERY {
        let mut x = rhs;
        lu.solve(&mut x);
        assert!(lu.refining && err(&x) < 1e-15, "solve {k}: {:e}", err(&x));
    }
    let (pattern, late, values) = augmented(7, 6, 5, 2);
    let mut fast = PivotFree::new(&pattern, &late, Rule::OneSide);
    let mut slow = SparseLu::new(&pattern)?;
    slow.factor(&values)?;
    let rhs: Vec<f64> = (0..pattern.n).map(|i| (i as f64 * 0.37).sin()).collect();
    let mut want = rhs.clone();
    slow.solve(&mut want)?;
    let size = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..=CHECK_EVERY {
        assert!(fast.factor(&values).is_ok(), "factorization {k}");
        let mut x = rhs.clone();
        fast.solve(&mut x);
        let e = (x.iter().zip(&want)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / size;
        let checked = k % CHECK_EVERY == 0;
        assert!(
            fast.checked == checked && !fast.refining && e < 1.3e-13,
            "factorization {k}: checked {}, {e:e}",
            fast.checked
        );
    }
    Ok(())
}

/// Small systems are factored as one dense block ([`dense::DENSE_MAX`]): in the same order,
/// their substitutions agree with the supernodal factors' to round-off (17, 44, 51 and 72
/// unknowns: measured 2.8e-16, 4.0e-15, 3.7e-15 and 4.0e-16 of the largest entry apart;
/// unrefined). Their sparse patterns leave most of each dense column outside the factors'
/// reach, which the elimination skips: its rows and columns fall in up to 2 runs each. The
/// places it neither sets nor zeroes before a factorization are never read (NaN there does not
/// reach the solution).
#[test]
fn the_dense_path_solves_as_the_supernodal_one() {
    let mut most = (0, 0);
    for (nodes, w, k) in [(2, 6, 5), (4, 6, 5), (12, 3, 1), (10, 6, 1)] {
        let (pattern, late, values) = augmented(nodes, w, k, 3);
        assert!(pattern.n <= dense::DENSE_MAX, "{} unknowns", pattern.n);
        let rhs: Vec<f64> = (0..pattern.n).map(|i| (i as f64 * 0.61).cos()).collect();
        let mut x = [rhs.clone(), rhs.clone()];
        for (make, x) in [PivotFree::new, PivotFree::supernodal]
            .into_iter()
            .zip(&mut x)
        {
            let mut lu = make(&pattern, &late, Rule::OneSide);
            if let Some(dense) = &mut lu.dense {
                let (rows, cols) = dense.most_runs();
                most = (most.0.max(rows), most.1.max(cols));
                // What the factorization does not set, it must not read.
                dense.poison();
            }
            assert!(lu.factor(&values).is_ok(), "{nodes} nodes of {w}");
            lu.substitute(x);
            assert!(x.iter().all(|v| v.is_finite()), "{nodes} nodes of {w}");
        }
        let size = x[1].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let gap = (x[0].iter().zip(&x[1])).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            gap <= 1.2e-14 * size,
            "{nodes} nodes of {w}: {:e}",
            gap / size
        );
    }
    eprintln!("most runs of rows and of columns: {most:?}");
    assert!(most.0 > 1 && most.1 > 1, "{most:?}");
}
