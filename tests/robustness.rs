//! Robustness: thousands of mutated versions of the shipped models and stdlib modules (tokens
//! deleted, duplicated, swapped, files truncated, random bytes spliced in) go through the
//! compiler. It must never panic or hang: every input compiles or is reported with a
//! diagnostic, `mbd check` exits 0 or 1 within a wall-clock limit, and a mutant that checks
//! runs a few steps or fails with a reported error.

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

/// Compiles one mutant in-process: `Ok(true)` compiled, `Ok(false)` rejected with an error.
fn compile_mutant(name: &str, input: &str) -> bool {
    if mbd::is_library(input) {
        return mbd::check_library(name, input, &mbd::model::NoFiles).is_ok();
    }
    match mbd::compile(name, input, &[], Request::default()) {
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

/// The compiler on 8,000 mutants in-process (fast), on a worker thread watched by this one: a
/// mutant that takes more than 10 s (a hang, or a cost out of all proportion: the largest
/// model compiles in milliseconds) fails the test with its text.
#[test]
fn mutated_models_never_panic_or_hang() {
    use std::sync::mpsc;
    use std::sync::{Arc, Mutex};
    let current = Arc::new(Mutex::new(String::new()));
    let (tx, rx) = mpsc::channel::<Result<bool, String>>();
    let watched = Arc::clone(&current);
    std::thread::spawn(move || {
        let corpus = corpus();
        let mut rng = Lcg(0x5eed_1234);
        let per_file = 8000 / corpus.len();
        for (name, text) in &corpus {
            for k in 0..per_file {
                let input = mutate(text, &mut rng);
                *watched.lock().expect("lock") = format!("mutation {k} of {name}:\n{input}");
                let result =
                    std::panic::catch_unwind(|| compile_mutant(name, &input)).map_err(|_| {
                        format!("the compiler panicked on mutation {k} of {name}:\n{input}")
                    });
                if tx.send(result).is_err() {
                    return;
                }
            }
        }
    });
    let (mut compiled, mut rejected) = (0, 0);
    loop {
        match rx.recv_timeout(std::time::Duration::from_secs(10)) {
            Ok(Ok(true)) => compiled += 1,
            Ok(Ok(false)) => rejected += 1,
            Ok(Err(panicked)) => panic!("{panicked}"),
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                panic!("no answer within 10 s on {}", current.lock().expect("lock"))
            }
        }
    }
    assert!(compiled + rejected >= 7000, "{compiled} + {rejected}");
    // The mutations must exercise both outcomes, or the test proves little.
    assert!(
        compiled > 50 && rejected > 1000,
        "compiled {compiled}, rejected {rejected}"
    );
}

/// Runs the binary with a wall-clock limit; `None` if it had to be killed.
fn run_limited(
    args: &[&std::ffi::OsStr],
    limit: std::time::Duration,
) -> Option<std::process::Output> {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mbd"))
        .args(args)
        .env("NO_COLOR", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mbd runs");
    // Read both pipes as the child writes: a report longer than a pipe holds (a 2 MB line
    // shown in a diagnostic) must not block the child and look like a hang.
    let drain = |pipe: Option<Box<dyn std::io::Read + Send>>| {
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut buf);
            }
            buf
        })
    };
    let out = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn std::io::Read + Send>),
    );
    let err = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn std::io::Read + Send>),
    );
    let started = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return Some(std::process::Output {
                status,
                stdout: out.join().unwrap_or_default(),
                stderr: err.join().unwrap_or_default(),
            });
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// Mutants through the binary, each under a wall-clock limit: `mbd check` exits 0 or 1 within
/// 10 s, and a model that checks runs 3 steps (`--steps 3`: the whole run in three large steps)
/// and exits 0, 1 (an error found as the run starts) or 3 (a run-time failure, reported)
/// within 30 s: never a panic (101), a signal, or a hang.
#[test]
fn mutated_models_exit_zero_or_one_and_run_or_fail_cleanly() {
    use std::ffi::OsStr;
    use std::time::Duration;
    let corpus = corpus();
    let mut rng = Lcg(0xfeed_beef);
    let dir = std::env::temp_dir().join(format!("mbd-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let out = dir.join("out.csv");
    let (mut ran, mut checked) = (0, 0);
    for (name, text) in &corpus {
        for k in 0..16 {
            let input = mutate(text, &mut rng);
            let path = dir.join(format!("m{k}.mbd"));
            std::fs::write(&path, &input).expect("write");
            let check = [OsStr::new("check"), path.as_os_str()];
            let o = run_limited(&check, Duration::from_secs(10))
                .unwrap_or_else(|| panic!("mbd check hung on a mutation of {name}:\n{input}"));
            let code = o.status.code();
            assert!(
                code == Some(0) || code == Some(1),
                "mbd check exited {code:?} on a mutation of {name}:\n{input}\n{}",
                String::from_utf8_lossy(&o.stderr)
            );
            checked += 1;
            if code != Some(0) || mbd::is_library(&input) {
                continue;
            }
            let run = [
                OsStr::new("run"),
                path.as_os_str(),
                OsStr::new("--steps"),
                OsStr::new("3"),
                OsStr::new("-o"),
                out.as_os_str(),
            ];
            let o = run_limited(&run, Duration::from_secs(30))
                .unwrap_or_else(|| panic!("mbd run hung on a mutation of {name}:\n{input}"));
            let code = o.status.code();
            assert!(
                matches!(code, Some(0) | Some(1) | Some(3)),
                "mbd run exited {code:?} on a mutation of {name}:\n{input}\n{}",
                String::from_utf8_lossy(&o.stderr)
            );
            ran += 1;
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    // Both paths must be exercised, or the test proves little.
    assert!(
        checked == 16 * corpus.len() && ran >= 10,
        "checked {checked}, ran {ran}"
    );
}

/// Byte-level mutations through the binary (issue 21): bytes that are not UTF-8, NUL, deep
/// nesting, a very long line, a long operator chain, and a generated 50,000-line model. Each
/// gets an answer within 20 s: exit 0, or exit 1 with a coded diagnostic; never a panic, a
/// crash (a signal) or a hang.
#[test]
fn byte_level_mutations_get_coded_answers() {
    use std::ffi::OsStr;
    use std::time::Duration;
    let corpus = corpus();
    let mut rng = Lcg(0x0b17_e5ed);
    let dir = std::env::temp_dir().join(format!("mbd-bytes-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let mut inputs: Vec<(String, Vec<u8>)> = Vec::new();
    for (name, text) in corpus.iter().step_by(3) {
        let bytes = text.as_bytes();
        let at = |rng: &mut Lcg| {
            let mut k = rng.below(bytes.len() + 1);
            while !text.is_char_boundary(k) {
                k -= 1;
            }
            k
        };
        let splice = |k: usize, insert: &[u8]| [&bytes[..k], insert, &bytes[k..]].concat();
        for insert in [
            &[0xFFu8][..],
            &[0xC3][..],
            &[0xE2, 0x82][..],
            &[0x00][..],
            &b"(((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((("[..],
        ] {
            let k = at(&mut rng);
            inputs.push((format!("{name} + {insert:02X?} at {k}"), splice(k, insert)));
        }
        let long_line = format!("\n# {}\n", "x".repeat(2_000_000));
        inputs.push((
            format!("{name} + a 2 MB line"),
            splice(at(&mut rng), long_line.as_bytes()),
        ));
        let chain = format!("\nparam zz = {}\n", vec!["1"; 50_000].join(" + "));
        inputs.push((
            format!("{name} + a 50,000-term sum"),
            [bytes, chain.as_bytes()].concat(),
        ));
    }
    // 50,000 params, each using the one before: a dependency chain evaluated from its end.
    let generated: String = std::iter::once(
        "model big\nground earth\npoint_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n\
         joint rope = distance(earth, bob)\nparam p0 = 0 m\n"
            .to_string(),
    )
    .chain((1..50_000).map(|i| format!("param p{i} = {i} m + p{} * 0\n", i - 1)))
    .chain(std::iter::once(
        "initial velocity of bob = (p49999 / 1 s, 0, 0)\nsolve hht { dt = 1 ms, until = 1 s }\n"
            .into(),
    ))
    .collect();
    inputs.push((
        "a generated 50,000-line model".into(),
        generated.into_bytes(),
    ));
    let code_re = |s: &str| {
        s.as_bytes()
            .windows(5)
            .any(|w| (w[0] == b'E' || w[0] == b'W') && w[1..].iter().all(u8::is_ascii_digit))
    };
    let (mut accepted, mut rejected) = (0, 0);
    for (k, (what, input)) in inputs.iter().enumerate() {
        let path = dir.join(format!("b{k}.mbd"));
        std::fs::write(&path, input).expect("write");
        let o = run_limited(
            &[OsStr::new("check"), path.as_os_str()],
            Duration::from_secs(20),
        )
        .unwrap_or_else(|| panic!("mbd check hung on {what}"));
        let err = String::from_utf8_lossy(&o.stderr);
        match o.status.code() {
            Some(0) => accepted += 1,
            Some(1) if code_re(&err) => rejected += 1,
            c => panic!(
                "mbd check exited {c:?} on {what}: {}",
                &err[..err.len().min(2000)]
            ),
        }
        if input.contains(&0xFF) {
            assert!(err.contains("E0104"), "{what}: {err}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        rejected > inputs.len() / 2 && accepted >= 1,
        "accepted {accepted}, rejected {rejected}"
    );
}
