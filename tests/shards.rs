//! Issue 24 item 2: a sweep cut into shares (`mbd stability --shard K/N`) and joined again
//! (`mbd merge`) is the unsharded sweep, bit for bit: its CSV (modes followed along the whole
//! grid) and its chart; shares that do not make one sweep are refused.

use crate::cli::{code, mbd, stderr, temp};

const SWEEP: &str = "Omega_bar=0.9:2.6:0.1";

fn path(p: &std::path::Path) -> &str {
    p.to_str().expect("path")
}

/// Runs share `k` of `n` with extra flags; returns its file.
fn share(k: usize, n: usize, extra: &[&str]) -> std::path::PathBuf {
    let out = temp(&format!("share_{k}_{n}_{}.json", extra.len()), "");
    let shard = format!("{k}/{n}");
    let mut args = vec!["stability", "models/windmill.mbd", "--sweep", SWEEP];
    args.extend(["--shard", &shard, "-o", path(&out)]);
    args.extend(extra);
    let o = mbd(&args);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(
        said.contains(&format!("share {k}/{n}: Omega_bar = ")),
        "{said}"
    );
    out
}

#[test]
fn three_shares_merged_are_the_unsharded_sweep_bit_for_bit() {
    // The windmill's grid has an edge in the first share (1.18) and in the last (2.32), so
    // both bisections and the modes' tracks cross the shares.
    let (csv, svg) = (temp("whole.csv", ""), temp("whole.svg", ""));
    let o = mbd(&[
        "stability",
        "models/windmill.mbd",
        "--sweep",
        SWEEP,
        "-o",
        path(&csv),
        "--chart",
        path(&svg),
        "--chart-kind",
        "campbell",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let shares: Vec<_> = (1..=3).map(|k| share(k, 3, &[])).collect();
    let (merged, merged_svg) = (temp("merged.csv", ""), temp("merged.svg", ""));
    // In any order.
    let o = mbd(&[
        "merge",
        path(&shares[2]),
        path(&shares[0]),
        path(&shares[1]),
        "-o",
        path(&merged),
        "--chart",
        path(&merged_svg),
        "--chart-kind",
        "campbell",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let read = |p: &std::path::Path| std::fs::read(p).expect("output");
    let whole_csv = String::from_utf8(read(&csv)).expect("utf-8");
    assert!(whole_csv.contains("mode5_freq"), "{whole_csv}");
    assert_eq!(whole_csv.lines().count(), 19);
    assert!(read(&merged) == read(&csv), "the merged CSV differs");
    assert!(read(&merged_svg) == read(&svg), "the merged chart differs");
    let said = String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("unstable: 1.17"), "{said}");

    // Two of three: the missing one is named.
    let o = mbd(&[
        "merge",
        path(&shares[0]),
        path(&shares[2]),
        "-o",
        path(&merged),
    ]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("shares missing: 2/3"), "{}", stderr(&o));
    // The same share twice.
    let o = mbd(&[
        "merge",
        path(&shares[0]),
        path(&shares[0]),
        path(&shares[1]),
        "-o",
        path(&merged),
    ]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("share 1 is given twice"),
        "{}",
        stderr(&o)
    );
    // A share of another sweep (another threshold).
    let other = share(2, 3, &["--threshold", "0.02"]);
    let o = mbd(&[
        "merge",
        path(&shares[0]),
        path(&other),
        path(&shares[2]),
        "-o",
        path(&merged),
    ]);
    assert_eq!(code(&o), 2);
    assert!(stderr(&o).contains("threshold differs"), "{}", stderr(&o));
    // Not a share.
    let o = mbd(&["merge", path(&csv), "-o", path(&merged)]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("is not a share of a sweep"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_shard_outside_the_grid_is_a_usage_error() {
    let out = temp("bad_share.json", "");
    for (shard, says) in [
        ("4/3", "1 <= K <= N"),
        ("0/3", "1 <= K <= N"),
        ("1/30", "the sweep has 18 values, so at most 18 shares"),
        ("x", "K/N"),
    ] {
        let o = mbd(&[
            "stability",
            "models/windmill.mbd",
            "--sweep",
            SWEEP,
            "--shard",
            shard,
            "-o",
            path(&out),
        ]);
        assert_eq!(code(&o), 2, "{shard}");
        assert!(stderr(&o).contains(says), "{shard}: {}", stderr(&o));
    }
    // The chart belongs to the merge.
    let o = mbd(&[
        "stability",
        "models/windmill.mbd",
        "--sweep",
        SWEEP,
        "--shard",
        "1/3",
        "-o",
        path(&out),
        "--chart",
        "x.svg",
    ]);
    assert_eq!(code(&o), 2);
}
