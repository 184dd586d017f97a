//! `cargo xtask docs [--check]`: every fenced block of README.md and of every page under
//! docs/ is run as a reader would run it, or is written by the command it shows.
//!
//! A block's info string says what it is and its annotation, an HTML comment on the
//! line above its fence, how it is run (docs/README.md, "Every block runs"): shell
//! and Python blocks run from the repository's root; Rust blocks are doctests of a
//! page `src/lib.rs` includes; a text block is the output of a command, an extract of
//! it, or a transcript of commands and their output, each compared with what the
//! command prints now; a block a named test runs names it; a drawing is a drawing. A
//! block that none of these covers fails the check, and the few that cannot run here
//! (flashing a real board) say why and are listed by every run.
//!
//! Without `--check`, the text blocks that differ from what their commands print are
//! written again (an extract keeps its lines, each replaced by the printed line most
//! like it); with it, they fail. `cargo test` checks every annotation without running
//! anything.

pub mod blocks;
mod run;

use blocks::{Block, How};
use std::collections::HashMap;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// `cargo xtask docs`'s options.
#[derive(clap::Args)]
pub struct Args {
    /// Fail if a text block differs from what its command prints, instead of writing it.
    #[arg(long)]
    check: bool,
    /// List every block and how it is run; run nothing.
    #[arg(long)]
    list: bool,
    /// The Python that runs the Python blocks (one with the package installed).
    #[arg(long, value_name = "PYTHON", default_value = "python3")]
    python: String,
    /// Only these pages (paths from the repository's root); every page by default.
    #[arg(long, value_name = "PAGE")]
    page: Vec<String>,
}

/// What became of one block.
enum Verdict {
    /// Run here, or compared with what its command printed, and as shown.
    Ran(f64),
    /// Run elsewhere: by `cargo test` (a doctest), `.ci/run` or a named test.
    Elsewhere(String),
    /// A drawing.
    Drawing,
    /// Not run, for this reason.
    NotRun(String),
    /// Written again from what its command printed.
    Written,
    Failed(String),
}

/// A text block's lines as they should be.
struct Edit {
    page: String,
    line: usize,
    old_len: usize,
    body: Vec<String>,
}

struct Runner<'a> {
    root: &'a Path,
    python: &'a str,
    write: bool,
    printed: HashMap<String, run::Ran>,
    edits: Vec<Edit>,
}

impl Runner<'_> {
    /// What `command` prints, run once per check.
    fn printed(&mut self, command: &str) -> Result<&run::Ran, String> {
        if !self.printed.contains_key(command) {
            let ran = run::shell(self.root, command);
            self.printed.insert(command.to_string(), ran);
        }
        let ran = &self.printed[command];
        if ran.ok {
            Ok(ran)
        } else {
            Err(format!(
                "`{command}` failed:\n{}\n{}",
                run::tail(&ran.stdout, 10),
                run::tail(&ran.stderr, 20)
            ))
        }
    }

    /// `body` replaces the block's lines (without `--check`), or the check fails.
    fn differs(&mut self, block: &Block, body: Vec<String>, what: String) -> Verdict {
        if self.write {
            self.edits.push(Edit {
                page: block.page.clone(),
                line: block.line,
                old_len: block.body.len(),
                body,
            });
            Verdict::Written
        } else {
            Verdict::Failed(format!(
                "{what}\n  run `cargo xtask docs --page {}` to write it again",
                block.page
            ))
        }
    }

    fn block(&mut self, block: &Block, how: &How) -> Verdict {
        let start = Instant::now();
        match how {
            How::Doctest => Verdict::Elsewhere("a doctest: cargo test runs it".into()),
            How::Ci => Verdict::Elsewhere(".ci/run runs its commands as written".into()),
            How::Test { file, name } => Verdict::Elsewhere(format!("{file}::{name} runs it")),
            How::Drawing => Verdict::Drawing,
            How::NotRun { reason } => Verdict::NotRun(reason.clone()),
            How::Run { writes, .. } => self.run_block(block, how, writes),
            How::Output { command } => {
                let printed = match self.printed(command) {
                    Ok(r) => r.stdout.clone(),
                    Err(e) => return Verdict::Failed(e),
                };
                let (shown, now) = (run::lines(&block.text()).join("\n"), run::lines(&printed));
                if shown == now.join("\n") {
                    Verdict::Ran(start.elapsed().as_secs_f64())
                } else {
                    let body = now.iter().map(|s| s.to_string()).collect();
                    self.differs(block, body, format!("not what `{command}` prints now"))
                }
            }
            How::Extract { command } => {
                let printed = match self.printed(command) {
                    Ok(r) => r.stdout.clone(),
                    Err(e) => return Verdict::Failed(e),
                };
                match run::extract(&block.body, &printed) {
                    Ok(()) => Verdict::Ran(start.elapsed().as_secs_f64()),
                    Err((fixed, differ)) => self.differs(
                        block,
                        fixed,
                        format!(
                            "lines `{command}` does not print:\n    {}",
                            differ.join("\n    ")
                        ),
                    ),
                }
            }
            How::Transcript => {
                let mut body = Vec::new();
                let mut differ = Vec::new();
                for (command, shown) in run::transcript(&block.body) {
                    let script = command.join("\n");
                    let ran = run::shell(self.root, &script);
                    if !ran.ok {
                        return Verdict::Failed(format!(
                            "`{script}` failed:\n{}",
                            run::tail(&ran.stderr, 20)
                        ));
                    }
                    let now = run::lines(&ran.stdout);
                    if now != shown.iter().map(|s| s.trim_end()).collect::<Vec<_>>() {
                        differ.push(format!("`{script}` prints:\n{}", now.join("\n")));
                    }
                    if !body.is_empty() {
                        body.push(String::new());
                    }
                    body.extend(
                        command
                            .iter()
                            .enumerate()
                            .map(|(i, l)| if i == 0 { format!("$ {l}") } else { l.clone() }),
                    );
                    body.extend(now.iter().map(|s| s.to_string()));
                }
                if differ.is_empty() {
                    Verdict::Ran(start.elapsed().as_secs_f64())
                } else {
                    self.differs(block, body, differ.join("\n"))
                }
            }
        }
    }

    /// Runs a shell or Python block; the files it declares are checked to exist and
    /// removed, and it may leave no other file behind.
    fn run_block(&mut self, block: &Block, how: &How, writes: &[String]) -> Verdict {
        let before = run::untracked(self.root);
        let script = run::script(block, how);
        let ran = if block.lang() == "python" {
            let tag = format!("{}-{}", block.page.replace(['/', '.'], "-"), block.line);
            run::python(self.root, self.python, &script, &tag)
        } else {
            run::shell(self.root, &script)
        };
        let mut problems = Vec::new();
        if !ran.ok {
            problems.push(format!(
                "failed:\n{}\n{}",
                run::tail(&ran.stdout, 10),
                run::tail(&ran.stderr, 20)
            ));
        }
        for file in writes {
            let path = self.root.join(file);
            if !path.exists() {
                problems.push(format!("did not write {file}"));
            } else if let Err(e) = std::fs::remove_file(&path) {
                problems.push(format!("cannot remove {file}: {e}"));
            }
        }
        let left: Vec<String> = run::untracked(self.root)
            .into_iter()
            .filter(|f| !before.contains(f))
            .collect();
        if !left.is_empty() {
            problems.push(format!(
                "left files behind (declare them with `writes`): {}",
                left.join(" ")
            ));
        }
        if problems.is_empty() {
            Verdict::Ran(ran.seconds)
        } else {
            Verdict::Failed(problems.join("\n"))
        }
    }
}

/// Applies the edits to their pages, each page's from its last block up.
fn apply(root: &Path, mut edits: Vec<Edit>) -> Result<(), String> {
    edits.sort_by(|a, b| (&a.page, b.line).cmp(&(&b.page, a.line)));
    for edit in edits {
        let path = root.join(&edit.page);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", edit.page))?;
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        // The fence is line `edit.line` (1-based): its body starts on the next.
        let start = edit.line;
        lines.splice(start..start + edit.old_len, edit.body);
        let mut out = lines.join("\n");
        if text.ends_with('\n') {
            out.push('\n');
        }
        std::fs::write(&path, out).map_err(|e| format!("{}: {e}", edit.page))?;
        eprintln!("wrote {}:{}", edit.page, edit.line);
    }
    Ok(())
}

/// `cargo xtask docs`.
pub fn run(args: &Args) -> ExitCode {
    let root = crate::root();
    let root = root.canonicalize().unwrap_or(root);
    let all = match blocks::all(&root) {
        Ok(all) => all,
        Err(e) => {
            eprintln!("xtask docs: {e}");
            return ExitCode::FAILURE;
        }
    };
    let wanted = |b: &Block| args.page.is_empty() || args.page.contains(&b.page);
    let start = Instant::now();
    let mut runner = Runner {
        root: &root,
        python: &args.python,
        write: !args.check,
        printed: HashMap::new(),
        edits: Vec::new(),
    };
    let (mut failed, mut not_run, mut counts) = (Vec::new(), Vec::new(), HashMap::new());
    for (block, how) in all.iter().filter(|(b, _)| wanted(b)) {
        let at = block.at();
        let verdict = match how {
            Err(e) => Verdict::Failed(e.clone()),
            Ok(how) if args.list => Verdict::Elsewhere(how.name().to_string()),
            Ok(how) => runner.block(block, how),
        };
        let name = how.as_ref().map_or("unannotated", How::name);
        *counts.entry(name).or_insert(0) += 1;
        let lang = if block.info.is_empty() {
            "-"
        } else {
            &block.info
        };
        match verdict {
            Verdict::Ran(s) => println!("ok      {at} {lang}: {name} ({s:.1} s)"),
            Verdict::Elsewhere(what) => println!("ok      {at} {lang}: {what}"),
            Verdict::Drawing => println!("ok      {at} {lang}: a drawing, nothing to run"),
            Verdict::Written => {
                println!("written {at} {lang}: {name}, from what its command prints")
            }
            Verdict::NotRun(reason) => {
                println!("not run {at} {lang}: {reason}");
                not_run.push(format!("{at}: {reason}"));
            }
            Verdict::Failed(e) => {
                println!("FAILED  {at} {lang}: {e}");
                failed.push(at);
            }
        }
    }
    if let Err(e) = apply(&root, std::mem::take(&mut runner.edits)) {
        eprintln!("xtask docs: {e}");
        return ExitCode::FAILURE;
    }
    let mut counts: Vec<_> = counts.into_iter().collect();
    counts.sort();
    let counts: Vec<String> = counts.iter().map(|(k, n)| format!("{n} {k}")).collect();
    let total = all.iter().filter(|(b, _)| wanted(b)).count();
    println!(
        "\n{total} blocks ({}) in {:.0} s",
        counts.join(", "),
        start.elapsed().as_secs_f64()
    );
    if !not_run.is_empty() {
        println!(
            "not run here, each with its reason:\n  {}",
            not_run.join("\n  ")
        );
    }
    if failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        println!("failed: {}", failed.join(" "));
        ExitCode::FAILURE
    }
}

#[cfg(test)]
mod tests {
    use super::blocks::*;

    /// Every block of every page is run by something or generated, and every
    /// annotation names what exists (the test, the doctest page, the CI command).
    /// Running them is `cargo xtask docs --check`'s, in CI.
    #[test]
    fn every_block_says_how_it_runs() {
        let root = crate::root();
        let problems: Vec<String> = all(&root)
            .unwrap()
            .into_iter()
            .filter_map(|(b, how)| how.err().map(|e| format!("{}: {e}", b.at())))
            .collect();
        assert!(problems.is_empty(), "{}", problems.join("\n"));
    }

    #[test]
    fn annotations() {
        assert_eq!(annotation("ci"), Ok(How::Ci));
        assert_eq!(
            annotation("output of `cargo run --example x -- 1`"),
            Ok(How::Output {
                command: "cargo run --example x -- 1".into()
            })
        );
        assert_eq!(
            annotation("run; writes a.bin b.csv; replace \"sudo apt\" with \"apt\""),
            Ok(How::Run {
                replace: vec![("sudo apt".into(), "apt".into())],
                writes: vec!["a.bin".into(), "b.csv".into()],
            })
        );
        assert_eq!(
            annotation("test tests/modbus/test_docs.py::test_commission (a node in QEMU)"),
            Ok(How::Test {
                file: "tests/modbus/test_docs.py".into(),
                name: "test_commission".into()
            })
        );
        assert!(annotation("not run:").is_err());
        assert!(annotation("run; sometimes").is_err());
        assert!(annotation("output of cargo run").is_err());
        assert!(annotation("skip").is_err());
    }

    #[test]
    fn blocks_and_their_defaults() {
        let page = "Text\n\n<!-- docs: drawing -->\n```text\n a\n```\n\n- item:\n  ```sh\n  ls\n  ```\n```\nx\n```\n";
        let blocks = parse("docs/x.md", page).unwrap();
        assert_eq!(blocks.len(), 3);
        assert_eq!(blocks[0].note.as_deref(), Some("drawing"));
        assert_eq!((blocks[1].line, blocks[1].lang()), (9, "sh"));
        assert_eq!(blocks[1].body, vec!["ls".to_string()]);
        let root = crate::root();
        assert!(matches!(how(&root, &blocks[1]), Ok(How::Run { .. })));
        // A block without a language on a page no doctest includes says nothing.
        assert!(how(&root, &blocks[2]).is_err());
        assert!(parse("x.md", "```sh\nls\n").is_err());
    }

    #[test]
    fn commands_of_a_script() {
        assert_eq!(
            commands("cargo fw   # the node\n\nprintf 'a # b' \\\n    | cat\n# a comment\n"),
            vec!["cargo fw".to_string(), "printf 'a # b' | cat".to_string()]
        );
    }
}
