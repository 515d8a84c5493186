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
