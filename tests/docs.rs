//! The language reference compiles: every ```mbd block of docs/language.md is a complete model
//! the compiler accepts (without warnings; a ```mbd,warning block with one), and every ```mbd,error
//! block is rejected, with the
//! code its `# error EXXXX` comment names. Blocks with any other tag (```text, ```sh) are prose.

use mbd::diagnostics::render_human;
use mbd::settings::Request;

const DOC: &str = "docs/language.md";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Expect {
    /// ```mbd: compiles.
    Accept,
    /// ```mbd,error: is rejected.
    Reject,
    /// ```mbd,warning: compiles, with a warning (what the example shows).
    Warn,
}

/// One compiled example: its number among the examples (from 1), the line of its opening fence,
/// and its text.
struct Example {
    index: usize,
    line: usize,
    expect: Expect,
    text: String,
}

impl Example {
    fn name(&self) -> String {
        format!("{DOC}#{}", self.index)
    }

    fn compile(&self) -> Result<mbd::Compiled, mbd::CompileFailure> {
        mbd::compile(&self.name(), &self.text, &[], Request::default())
    }

    fn describe(&self) -> String {
        format!(
            "example {} (line {} of {DOC}):\n{}",
            self.index, self.line, self.text
        )
    }

    /// The code named by a `# error EXXXX` comment, if any.
    fn expected_code(&self) -> Option<&str> {
        let at = self.text.find("error E")? + "error ".len();
        let code = self.text.get(at..at + 5)?;
        code[1..]
            .bytes()
            .all(|b| b.is_ascii_digit())
            .then_some(code)
    }
}

/// The ```mbd and ```mbd,error blocks of the reference, in order.
fn examples() -> Vec<Example> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(DOC);
    let doc = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    // An open block: its tag's expectation (None: not compiled), first line, text.
    let mut open: Option<(Option<Expect>, usize, String)> = None;
    let mut out = Vec::new();
    for (n, line) in doc.lines().enumerate() {
        let trimmed = line.trim();
        if let Some((expect, start, mut text)) = open.take() {
            if trimmed == "```" {
                if let Some(expect) = expect {
                    out.push(Example {
                        index: out.len() + 1,
                        line: start,
                        expect,
                        text,
                    });
                }
            } else {
                text.push_str(line);
                text.push('\n');
                open = Some((expect, start, text));
            }
        } else if let Some(tag) = trimmed.strip_prefix("```") {
            let expect = match tag.trim() {
                "mbd" => Some(Expect::Accept),
                "mbd,error" => Some(Expect::Reject),
                "mbd,warning" => Some(Expect::Warn),
                _ => None,
            };
            open = Some((expect, n + 1, String::new()));
        }
    }
    if let Some((_, start, _)) = open {
        panic!("{DOC}: the code block opened on line {start} is never closed");
    }
    out
}

fn render(failure: &mbd::CompileFailure) -> String {
    failure
        .diagnostics
        .iter()
        .map(|d| render_human(d, &failure.sources, false))
        .collect()
}

#[test]
fn docs_have_enough_examples() {
    let all = examples();
    let accept = all.iter().filter(|e| e.expect == Expect::Accept).count();
    let reject = all.iter().filter(|e| e.expect == Expect::Reject).count();
    assert!(
        accept >= 30,
        "{DOC} has only {accept} ```mbd examples; the reference shows a complete model for every construct"
    );
    assert!(reject >= 1, "{DOC} has no ```mbd,error examples");
}

#[test]
fn every_mbd_example_compiles() {
    let mut failures = Vec::new();
    for e in examples().iter().filter(|e| e.expect != Expect::Reject) {
        if let Err(f) = e.compile() {
            failures.push(format!("{}\n{}", e.describe(), render(&f)));
        }
    }
    assert!(
        failures.is_empty(),
        "{} ```mbd example(s) do not compile:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn mbd_examples_have_no_warnings() {
    let mut noisy = Vec::new();
    for e in examples().iter().filter(|e| e.expect == Expect::Accept) {
        if let Ok(c) = e.compile() {
            if !c.warnings.is_empty() {
                let text: String = c
                    .warnings
                    .iter()
                    .map(|d| render_human(d, &c.sources, false))
                    .collect();
                noisy.push(format!("{}\n{text}", e.describe()));
            }
        }
    }
    assert!(
        noisy.is_empty(),
        "{} ```mbd example(s) compile with warnings:\n\n{}",
        noisy.len(),
        noisy.join("\n\n")
    );
    for e in examples().iter().filter(|e| e.expect == Expect::Warn) {
        if let Ok(c) = e.compile() {
            assert!(!c.warnings.is_empty(), "{} warns of nothing", e.describe());
        }
    }
}

#[test]
fn every_error_example_is_rejected() {
    let mut failures = Vec::new();
    for e in examples().iter().filter(|e| e.expect == Expect::Reject) {
        match e.compile() {
            Ok(_) => failures.push(format!(
                "{}\ncompiled, but is tagged mbd,error",
                e.describe()
            )),
            Err(f) => {
                if let Some(code) = e.expected_code() {
                    if !f.diagnostics.iter().any(|d| d.code.as_str() == code) {
                        failures.push(format!(
                            "{}\nis rejected, but without the {code} its comment names:\n{}",
                            e.describe(),
                            render(&f)
                        ));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} ```mbd,error example(s) misbehave:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}
