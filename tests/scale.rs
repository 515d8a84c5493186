//! The compiler at any model size (issue 21): the rank checks run on every model, however
//! large, and find the same faults far from the ground as near it; many diagnostics render
//! in time linear in their number, summarised per code for people, every one in JSON.

use crate::cli::{code, mbd, stderr};
use crate::common::repo;
use mbd::diagnostics::{render_human, summarize, Code, Diagnostic};
use mbd::settings::Request;

/// `models/chain.mbd` (a planar chain of rods hinged end to end, pinned to the ground at its
/// start) at `n` links, with `extra` declarations.
fn chain(n: usize, extra: &str) -> (String, Vec<String>) {
    let text = crate::common::read("models/chain.mbd");
    (format!("{text}{extra}\n"), vec![format!("links={n}")])
}

fn diagnostics((text, sets): &(String, Vec<String>)) -> Vec<Diagnostic> {
    match mbd::compile("chain.mbd", text, sets, Request::default()) {
        Ok(c) => c.warnings,
        Err(f) => f.diagnostics,
    }
}

/// 2,000 links are 12,000 virtual-motion columns: four times what the dense checks took
/// before they were skipped without a word.
#[test]
fn a_chain_of_two_thousand_links_gets_every_rank_check() {
    assert!(diagnostics(&chain(2000, "")).is_empty());
    // Far from the origin a small rod's rotary inertia is tiny in the checks' scaled
    // rotations; it is judged in SI, so a 10,000-link chain (1 km) is not short of inertia.
    assert!(diagnostics(&chain(10_000, "")).is_empty());
    // A second hinge on the last joint: five equations too many, at the far end.
    let d = diagnostics(&chain(
        2000,
        "joint again = revolute(rod[1999].end, rod[2000].start) { axis = z }",
    ));
    assert_eq!(d.len(), 1, "{:?}", d);
    assert_eq!(d[0].code, Code::W0303);
    assert!(
        d[0].message.starts_with(
            "redundant constraints: `hinge[1999]`, `again` lock the same motion (5 equations too many)"
        ),
        "{}",
        d[0].message
    );
    assert!(d[0]
        .hint
        .as_deref()
        .is_some_and(|h| h.contains("rank 10000 for 10005 equations")));
    // A slender rod on a ball joint at the tip spins about its axis with nothing to stop it.
    let d = diagnostics(&chain(
        2000,
        "rigid_rod tip { from = (200, 0, 0) m, to = (201, 0, 0) m, mass = 0.1 kg }\n\
         joint ball = spherical(rod[2000].end, tip.start)",
    ));
    assert_eq!(d.len(), 1, "{:?}", d);
    assert_eq!(d[0].code, Code::E0308);
    assert_eq!(
        d[0].message,
        "`tip` can move without inertia or restraint: rotation about (1.000, 0.000, 0.000)"
    );
}

/// A loop closed through the ground 50 links away: the whole loop is one block. In 3-D a
/// planar loop of parallel hinges locks three motions twice (out of the plane), and the
/// straight line it starts in locks its length twice: 4 equations too many.
#[test]
fn a_long_closed_loop_is_checked_as_one_block() {
    let d = diagnostics(&chain(
        50,
        "joint close = revolute(earth @ (5, 0, 0) m, rod[50].end) { axis = z }",
    ));
    assert_eq!(d.len(), 1, "{:?}", d);
    assert_eq!(d[0].code, Code::W0303);
    assert!(
        d[0].message.contains("(4 equations too many)"),
        "{}",
        d[0].message
    );
    assert_eq!(d[0].labels.len(), 51, "every joint of the loop takes part");
}

/// Blocks over 600 columns are reduced on a spanning tree instead of factored densely: on
/// each side of that size (90 links: 540 columns, dense; 110 links: 660, tree) the same
/// loops give the same dependencies, and a loop of 2,000 links (12,000 columns) is checked.
#[test]
fn large_loops_reduced_on_a_tree_agree_with_the_dense_check() {
    let closing = |n: usize, kind: &str| -> String {
        let x = n as f64 / 10.0;
        match kind {
            "spherical" => format!("joint close = spherical(earth @ ({x}, 0, 0) m, rod[{n}].end)"),
            _ => format!(
                "joint close = revolute(earth @ ({x}, 0, 0) m, rod[{n}].end) {{ axis = z }}"
            ),
        }
    };
    // Out of the plane 3 (revolute) or 1 (spherical), and the straight line's length once
    // more; bent into an arch, no straight line.
    for (kind, bent, too_many) in [
        ("revolute", false, 4),
        ("spherical", false, 2),
        ("revolute", true, 3),
    ] {
        for n in [90, 110] {
            let mut model = chain(n, &closing(n, kind));
            if bent {
                model.0 = model.0.replace(
                    "from = ((i - 1) * l, 0, 0), to = (i * l, 0, 0)",
                    &format!("from = ((i - 1) * l, 0.01 * (i - 1) * ({n} - i + 1) * l, 0), to = (i * l, 0.01 * i * ({n} - i) * l, 0)"),
                );
            }
            let d = diagnostics(&model);
            assert_eq!(d.len(), 1, "{kind} {n}: {:?}", d);
            // Dense blocks' surplus is dropped at run time (W0303); a loop reduced on a tree
            // is refused.
            let code = if n > 100 { Code::E0307 } else { Code::W0303 };
            assert_eq!(d[0].code, code, "{kind} {n}");
            let tail = format!("({too_many} equations too many)");
            assert!(d[0].message.contains(&tail), "{kind} {n}: {}", d[0].message);
            assert_eq!(
                d[0].labels.len(),
                n + 1,
                "{kind} {n}: every joint takes part"
            );
        }
    }
    let d = diagnostics(&chain(2000, &closing(2000, "revolute")));
    assert_eq!(d.len(), 1, "{:?}", d);
    assert_eq!(d[0].code, Code::E0307);
    assert!(
        d[0].message.contains("(4 equations too many)"),
        "{}",
        d[0].message
    );
    assert_eq!(d[0].labels.len(), 2001);
}

/// Many warnings of one code: ten shown, the rest counted; JSON lists every one. The window
/// each report reads is its own lines, so the last line of a long file renders with its
/// number.
#[test]
fn many_diagnostics_are_summarised_per_code_and_all_listed_in_json() {
    let n = 2500;
    let head = "model p\nground earth\npoint_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n\
                joint rope = distance(earth, bob)\n";
    let text: String = std::iter::once(head.to_string())
        .chain((0..n).map(|i| format!("param p{i} = {i}\n")))
        .chain(std::iter::once(
            "solve hht { dt = 1 ms, until = 1 s }\n".into(),
        ))
        .collect();
    let d = diagnostics(&(text.clone(), Vec::new()));
    assert_eq!(d.len(), n);
    let (shown, more) = summarize(&d, 10);
    assert_eq!(shown.len(), 10);
    assert_eq!(more, ["... and 2,490 more W0201 warnings"]);
    let c = match mbd::compile("p.mbd", &text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    let last = render_human(&c.warnings[n - 1], &c.sources, false);
    assert!(last.contains("2504 │ param p2499 = 2499"), "{last}");
    assert!(last.contains("2503 │ param p2498 = 2498"), "{last}");
    assert!(last.contains("[p.mbd:2504:1]"), "{last}");

    let dir = std::env::temp_dir().join(format!("mbd-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("params.mbd");
    std::fs::write(&path, &text).expect("write model");
    let p = path.to_string_lossy();
    let o = mbd(&["check", &p]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(err.matches("W0201").count(), 11, "{err}");
    assert!(err.contains("... and 2,490 more W0201 warnings"), "{err}");
    let o = mbd(&["check", &p, "--format", "json"]);
    let json: serde_json::Value = serde_json::from_str(&stderr(&o)).expect("JSON diagnostics");
    assert_eq!(json.as_array().map(|a| a.len()), Some(n));
    let _ = std::fs::remove_dir_all(dir);
}

/// One expression holds at most 1,000 operators, which bounds the depth of every recursive
/// pass over it: at the limit each kind of chain compiles, on a test thread's small stack;
/// past it, a coded error, never a stack overflow.
#[test]
fn long_operator_chains_compile_up_to_the_limit_and_are_refused_past_it() {
    let model = |value: &str| {
        format!(
            "model p\nground earth\nparam x = {value}\n\
             point_mass bob {{ mass = x * 1 kg, at = (0, -1, 0) m }}\n\
             joint rope = distance(earth, bob)\nsolve hht {{ dt = 1 ms, until = 1 s }}\n"
        )
    };
    let chains = |n: usize| {
        [
            vec!["1"; n + 1].join(" + "),
            vec!["1"; n + 1].join(" * "),
            vec!["1"; n + 1].join(" ^ "),
            format!("{}1", "-".repeat(n)),
        ]
    };
    for value in chains(1000) {
        let d = diagnostics(&(model(&value), Vec::new()));
        assert!(d.iter().all(|d| d.code.is_warning()), "{:?}", d.first());
    }
    for value in chains(1001) {
        let d = diagnostics(&(model(&value), Vec::new()));
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].code, Code::E0101);
        assert_eq!(
            d[0].message,
            "an expression of 1001 operators: more than 1000"
        );
    }
    // 50,000 terms on one line, through the binary: coded, exit 1.
    let dir = std::env::temp_dir().join(format!("mbd-chain-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("long.mbd");
    std::fs::write(&path, model(&vec!["1"; 50_000].join(" + "))).expect("write model");
    let o = mbd(&["check", &path.to_string_lossy()]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("an expression of 49999 operators"));
    let _ = std::fs::remove_dir_all(dir);
}

/// Bytes that are not UTF-8 are the model's fault (exit 1, E0104 at the first bad byte); a
/// byte-order mark and CRLF line ends are accepted; a directory is a usage error (exit 2).
#[test]
fn file_encodings_get_a_coded_answer() {
    let model = "model p\nground earth\npoint_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n\
                 joint rope = distance(earth, bob)\nsolve hht { dt = 1 ms, until = 1 s }\n";
    let dir = std::env::temp_dir().join(format!("mbd-bytes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, bytes).expect("write model");
        p.to_string_lossy().to_string()
    };
    let mut latin1 = model.replace("model p", "model p # 20 \u{b0}").into_bytes();
    let at = latin1
        .iter()
        .position(|&b| b == 0xC2)
        .expect("the degree sign");
    latin1.remove(at); // 0xB0 alone: Latin-1's degree sign
    let o = mbd(&["check", &write("latin1.mbd", &latin1)]);
    assert_eq!(code(&o), 1, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("E0104"), "{err}");
    assert!(err.contains("byte 0xB0 at line 1, column 14"), "{err}");
    let bom = [&[0xEF, 0xBB, 0xBF][..], model.as_bytes()].concat();
    let o = mbd(&["check", &write("bom.mbd", &bom)]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = mbd(&[
        "check",
        &write("crlf.mbd", model.replace('\n', "\r\n").as_bytes()),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = mbd(&["check", &dir.to_string_lossy()]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("is a directory"));
    let _ = std::fs::remove_dir_all(&dir);

    let (d, sources) = match mbd::syntax::decode("latin1.mbd", latin1) {
        Ok(_) => panic!("Latin-1 bytes decoded as UTF-8"),
        Err(e) => e,
    };
    assert_eq!(d.code, Code::E0104);
    insta::assert_snapshot!("not_utf8", render_human(&d, &sources, false));
    assert!(repo("tests/ui").is_dir());
}

/// Ctrl-C (SIGINT) stops a run after its step: exit 130, E0607 saying when, and a CSV of
/// whole rows, every one computed before the stop.
#[test]
fn ctrl_c_stops_a_run_and_keeps_its_rows() {
    let dir = std::env::temp_dir().join(format!("mbd-sigint-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let csv = dir.join("windmill.csv");
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_mbd"))
        .args(["run", "models/windmill.mbd", "--until", "1000", "-o"])
        .arg(&csv)
        .current_dir(repo(""))
        .env("NO_COLOR", "1")
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start mbd");
    // Wait for rows to be written (the run takes minutes), then interrupt it.
    let start = std::time::Instant::now();
    while std::fs::metadata(&csv).map_or(0, |m| m.len()) < 100_000 {
        assert!(start.elapsed().as_secs() < 60, "no rows after a minute");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(kill.success());
    let o = child.wait_with_output().expect("mbd ends");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("E0607"), "{err}");
    assert!(err.contains("run interrupted at t = "), "{err}");
    let text = std::fs::read_to_string(&csv).expect("the CSV");
    assert!(text.ends_with('\n'), "the last row is whole");
    let rows: Vec<&str> = text.lines().collect();
    let width = rows[0].split(',').count();
    assert!(rows.len() > 100, "{} rows", rows.len());
    assert!(rows.iter().all(|r| r.split(',').count() == width));
    assert!(rows.len() < 2_000_000, "the run went on to the end");
    let _ = std::fs::remove_dir_all(dir);
}

/// E0607 as a person reads it.
#[test]
fn an_interrupted_run_says_when_and_that_its_rows_are_kept() {
    let text = crate::common::read("models/pendulum.mbd");
    let c = match mbd::compile("models/pendulum.mbd", &text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    let f = mbd::solve::RuntimeFailure {
        kind: mbd::solve::FailureKind::Interrupted,
        t: 0.25,
        step: 51,
        entity: None,
        detail: "stopped before step 51 of 200".into(),
    };
    let d = c.failure_diagnostic(&f);
    assert_eq!(d.code, Code::E0607);
    insta::assert_snapshot!("run_interrupted", render_human(&d, &c.sources, false));
}

/// Bodies short of inertia that the joints do not hold are factored densely in groups: a
/// floating chain of 100 massless bodies gets E0308; one of 600 (3,600 free motions) would
/// take minutes, so it gets W0302, which says so, instead of a hang.
#[test]
fn a_large_group_of_massless_bodies_is_reported_unchecked_not_hung() {
    let floating = |n: usize| {
        format!(
            "model m\nground earth\n\
             for i in 1..={n} {{ rigid b[i] {{ mass = 0 kg, at = (i, 0, 0) m }} }}\n\
             for i in 1..{n} {{ joint ball[i] = spherical(b[i] @ (0.5, 0, 0) m, b[i + 1] @ (-0.5, 0, 0) m) }}\n\
             solve hht {{ dt = 1 ms, until = 1 s }}\n"
        )
    };
    let d = diagnostics(&(floating(100), Vec::new()));
    let codes: Vec<Code> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, [Code::W0301, Code::E0308], "{d:?}");
    let text = floating(600);
    let d = diagnostics(&(text.clone(), Vec::new()));
    let codes: Vec<Code> = d.iter().map(|d| d.code).collect();
    assert_eq!(codes, [Code::W0301, Code::W0302], "{d:?}");
    let c = match mbd::compile("m.mbd", &text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    insta::assert_snapshot!("massless_unchecked", render_human(&d[1], &c.sources, false));
}

/// A chain of definitions declared last-first is evaluated one inside another, as deep as
/// it is long: 10,000 deep compiles on a test thread's small stack (it grows on the heap),
/// one more is refused with a code.
#[test]
fn a_chain_of_definitions_in_reverse_is_evaluated_to_the_limit_and_refused_past_it() {
    let model = |n: usize| -> String {
        let head = "model big\nground earth\npoint_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n\
                    joint rope = distance(earth, bob)\n";
        let chain: String = (1..n)
            .rev()
            .map(|i| format!("param p{i} = {i} m + p{} * 0\n", i - 1))
            .collect();
        let tail = format!(
            "param p0 = 0 m\ninitial velocity of bob = (p{} / 1 s, 0, 0)\n\
             solve hht {{ dt = 1 ms, until = 1 s }}\n",
            n - 1
        );
        format!("{head}{chain}{tail}")
    };
    let d = diagnostics(&(model(10_000), Vec::new()));
    assert!(d.is_empty(), "{:?}", d.first());
    let d = diagnostics(&(model(10_001), Vec::new()));
    assert_eq!(d.len(), 1, "{:?}", d.first());
    assert_eq!(d[0].code, Code::E0207);
    assert_eq!(d[0].message, "definitions nest more than 10000 deep");
}
