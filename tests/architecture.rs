//! ARCHITECTURE.md stays true: every path it names exists, and the invariants it states hold.

use crate::common::{read, repo};

#[test]
fn every_path_named_in_architecture_md_exists() {
    let text = read("ARCHITECTURE.md");
    let mut checked = 0;
    for piece in text.split('`').skip(1).step_by(2) {
        let looks_like_path = (piece.starts_with("src/")
            || piece.starts_with("tests/")
            || piece.starts_with("grammar/")
            || piece.starts_with("models/")
            || piece.starts_with("benches/")
            || piece.starts_with(".ci/"))
            && !piece.contains(' ');
        if looks_like_path {
            assert!(
                repo(piece.trim_end_matches('/')).exists(),
                "ARCHITECTURE.md names {piece}, which does not exist"
            );
            checked += 1;
        }
    }
    assert!(
        checked >= 10,
        "ARCHITECTURE.md should name the code map's paths (found {checked})"
    );
}

fn rust_files(dir: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut stack = vec![repo(dir)];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("dir").filter_map(|e| e.ok()) {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().map(|x| x == "rs").unwrap_or(false) {
                let rel = p
                    .strip_prefix(repo(""))
                    .map(|r| r.to_string_lossy().to_string())
                    .unwrap_or_default();
                out.push((rel, std::fs::read_to_string(&p).expect("read")));
            }
        }
    }
    out
}

#[test]
fn only_solve_linear_imports_faer() {
    for (path, text) in rust_files("src") {
        if path != "src/solve/linear.rs" {
            assert!(
                !text.contains("faer::") && !text.contains("use faer"),
                "{path} uses faer"
            );
        }
    }
}

#[test]
fn only_syntax_knows_pest() {
    for (path, text) in rust_files("src") {
        if !path.starts_with("src/syntax/") {
            assert!(
                !text.contains("pest::") && !text.contains("pest_derive"),
                "{path} uses pest"
            );
        }
    }
}

#[test]
fn runtime_and_solve_know_nothing_of_spans() {
    for (path, text) in rust_files("src") {
        if path.starts_with("src/runtime/") || path.starts_with("src/solve/") {
            assert!(
                !text.contains("Span") && !text.contains("crate::source"),
                "{path} mentions spans"
            );
            assert!(
                !text.contains("crate::model") && !text.contains("crate::syntax"),
                "{path} reaches back up the pipeline"
            );
            assert!(
                !path.starts_with("src/solve/") || !text.contains("Element::"),
                "{path} matches concrete elements: the solve stage drives the runtime through its generic interface"
            );
        }
    }
}

#[test]
fn no_module_is_past_a_thousand_lines() {
    for (path, text) in rust_files("src") {
        assert!(
            text.lines().count() <= 1000,
            "{path} has {} lines: split it",
            text.lines().count()
        );
    }
}

#[test]
fn the_study_library_does_no_file_io() {
    for (path, text) in rust_files("src/study") {
        assert!(
            !text.contains("std::fs") && !text.contains("File::"),
            "{path} touches files: the CLI reads and writes them"
        );
    }
}

#[test]
fn the_references_do_not_use_the_library() {
    for (path, text) in rust_files("tests/reference") {
        // The bound checks are plain f64 too.
        let text = text
            .replace("use crate::common::{above, within};", "")
            .replace("use crate::common::within;", "");
        assert!(
            !text.contains("mbd::") && !text.contains("crate::") && !text.contains("extern crate"),
            "{path} reaches outside the references: they must stay plain f64"
        );
    }
}

/// The `fn`s of `text` as `(line, name, lines)`. A `fn` runs from its signature to the first later
/// line that is a closing brace at the signature's indentation (rustfmt's layout), as issue 17's
/// checker measures; a bodiless declaration (`fn f();`) is skipped.
fn fn_lengths(text: &str) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let rest = line.trim_start();
        let indent = &line[..line.len() - rest.len()];
        let Some(name) = fn_name(rest) else {
            continue;
        };
        if rest.ends_with(';') {
            continue;
        }
        let end = (i + 1..lines.len())
            .find(|&j| {
                let l = lines[j];
                l == format!("{indent}}}")
                    || (l.starts_with(&format!("{indent}}}")) && l.trim().len() <= 2)
            })
            .unwrap_or(lines.len().saturating_sub(1));
        out.push((i + 1, name, end - i + 1));
    }
    out
}

/// The name of the `fn` that `rest` (a line without its indentation) declares, if it does:
/// `[pub[(..)] ][const ][async ][unsafe ]fn NAME`.
fn fn_name(rest: &str) -> Option<String> {
    let mut s = rest;
    if let Some(after) = s.strip_prefix("pub(") {
        s = after.split_once(") ")?.1;
    } else if let Some(after) = s.strip_prefix("pub ") {
        s = after;
    }
    for qualifier in ["const ", "async ", "unsafe "] {
        s = s.strip_prefix(qualifier).unwrap_or(s);
    }
    let name: String = s
        .strip_prefix("fn ")?
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    (!name.is_empty()).then_some(name)
}

#[test]
fn no_file_is_past_600_lines_and_no_function_past_120() {
    let mut too_long = Vec::new();
    for dir in ["src", "tests", "benches"] {
        for (path, text) in rust_files(dir) {
            let n = text.lines().count();
            if n > 600 {
                too_long.push(format!("{path}: {n} lines"));
            }
            for (line, name, n) in fn_lengths(&text) {
                if n > 120 {
                    too_long.push(format!("{path}:{line}: fn {name} has {n} lines"));
                }
            }
        }
    }
    too_long.sort();
    assert!(
        too_long.is_empty(),
        "split these (at most 600 lines a file, 120 a function):\n{}",
        too_long.join("\n")
    );
}

#[test]
fn the_length_scan_measures_functions_as_rustfmt_lays_them_out() {
    let text = "fn a() {\n    1\n}\n\npub(crate) const fn b(\n    x: u8,\n) -> u8 {\n    x\n}\n\
trait T {\n    fn c(&self);\n    fn d(&self) {\n        let _ = '{';\n    }\n}\n";
    let found: Vec<(usize, String, usize)> = fn_lengths(text);
    let want = [(1, "a", 3), (5, "b", 5), (12, "d", 3)];
    assert_eq!(found, want.map(|(l, n, k)| (l, n.to_string(), k)).to_vec());
}
