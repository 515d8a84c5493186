//! Robustness: thousands of mutated versions of the shipped models and stdlib modules (tokens
//! deleted, duplicated, swapped, files truncated, random bytes spliced in) go through the
//! compiler. It must never panic or hang: every input compiles or is reported with a
//! diagnostic, and `mbd check` exits 0 or 1.

use crate::common::{read, repo};
use mbd::settings::Request;

/// A small deterministic generator (no dependency, reproducible failures).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Splits text into tokens and the whitespace between them, so mutations act on tokens.
fn tokens(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut start = 0;
    let mut kind = None;
    for (i, c) in text.char_indices() {
        let k = if c.is_whitespace() {
            0
        } else if c.is_alphanumeric() || c == '_' || c == '.' {
            1
        } else {
            2 + i
        };
        if Some(k) != kind || k >= 2 {
            if i > start {
                out.push(&text[start..i]);
            }
            start = i;
            kind = Some(k);
        }
    }
    out.push(&text[start..]);
    out
}

fn mutate(text: &str, rng: &mut Lcg) -> String {
    let mut t: Vec<String> = tokens(text).into_iter().map(|s| s.to_string()).collect();
    let n = t.len();
    match rng.below(6) {
        0 => {
            // Delete a few tokens.
            for _ in 0..1 + rng.below(3) {
                if !t.is_empty() {
                    let k = rng.below(t.len());
                    t.remove(k);
                }
            }
        }
        1 => {
            let k = rng.below(n);
            let dup = t[k].clone();
            t.insert(k, dup);
        }
        2 => {
            let (a, b) = (rng.below(n), rng.below(n));
            t.swap(a, b);
        }
        3 => {
            let s: String = t.concat();
            let mut cut = rng.below(s.len());
            while !s.is_char_boundary(cut) {
                cut -= 1;
            }
            return s[..cut].to_string();
        }
        4 => {
            const BYTES: &[&str] = &[
                "(",
                ")",
                "{",
                "}",
                "[",
                "]",
                "@",
                "=",
                ",",
                ":",
                "..",
                "^",
                "*",
                "/",
                "-",
                "0",
                "1e308",
                "\"",
                "#",
                "\u{0}",
                "é",
                "\n",
                "9",
                "x",
                "for",
                "use",
                "if",
                "component",
            ];
            for _ in 0..1 + rng.below(4) {
                let k = rng.below(n);
                t.insert(k, BYTES[rng.below(BYTES.len())].to_string());
            }
        }
        _ => {
            // Replace a number or a name with another token of the file.
            let (a, b) = (rng.below(n), rng.below(n));
            t[a] = t[b].clone();
        }
    }
    t.concat()
}

fn corpus() -> Vec<(String, String)> {
    let mut out = Vec::new();
    for dir in ["models", "stdlib"] {
        let mut names: Vec<String> = std::fs::read_dir(repo(dir))
            .expect(dir)
            .filter_map(|e| e.ok())
            .map(|e| format!("{dir}/{}", e.file_name().to_string_lossy()))
            .filter(|p| p.ends_with(".mbd"))
            .collect();
        names.sort();
        for n in names {
            let text = read(&n);
            out.push((n, text));
        }
    }
    out
}

#[test]
fn mutated_models_never_panic() {
    let corpus = corpus();
    let mut rng = Lcg(0x5eed_1234);
    let mut compiled = 0;
    let mut rejected = 0;
    let per_file = 8000 / corpus.len();
    for (name, text) in &corpus {
        for k in 0..per_file {
            let input = mutate(text, &mut rng);
            let started = std::time::Instant::now();
            let result = std::panic::catch_unwind(|| {
                if mbd::is_library(&input) {
                    mbd::check_library(name, &input, &mbd::model::NoFiles).is_ok()
                } else {
                    let ok = mbd::compile(name, &input, &[], Request::default());
                    match ok {
                        // Every rejection carries at least one error diagnostic.
                        Err(f) => {
                            assert!(
                                f.diagnostics.iter().any(|d| d.is_error()),
                                "rejected without an error"
                            );
                            false
                        }
                        Ok(_) => true,
                    }
                }
            });
            match result {
                Ok(true) => compiled += 1,
                Ok(false) => rejected += 1,
                Err(_) => panic!("the compiler panicked on mutation {k} of {name}:\n{input}"),
            }
            let took = started.elapsed();
            assert!(
                took.as_secs_f64() < 5.0,
                "mutation {k} of {name} took {took:?}:\n{input}"
            );
        }
    }
    assert!(compiled + rejected >= 7000, "{compiled} + {rejected}");
    // The mutations must exercise both outcomes, or the test proves little.
    assert!(
        compiled > 50 && rejected > 1000,
        "compiled {compiled}, rejected {rejected}"
    );
}

#[test]
fn mutated_models_exit_zero_or_one() {
    let corpus = corpus();
    let mut rng = Lcg(0xfeed_beef);
    let dir = std::env::temp_dir().join(format!("mbd-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for (name, text) in &corpus {
        for k in 0..6 {
            let input = mutate(text, &mut rng);
            let path = dir.join(format!("m{k}.mbd"));
            std::fs::write(&path, &input).expect("write");
            let o = std::process::Command::new(env!("CARGO_BIN_EXE_mbd"))
                .arg("check")
                .arg(&path)
                .output()
                .expect("mbd runs");
            let code = o.status.code();
            assert!(
                code == Some(0) || code == Some(1),
                "mbd check exited {code:?} on a mutation of {name}:\n{input}\n{}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
