//! The commands and scene files the README and the docs show keep working:
//! every `drape` command line of a fenced `sh` block runs (briefly: a run
//! simulates 0.05 s without recording, a bench is planned, not run, the
//! stability suite runs one quick case, `yank`, unless the command names its
//! own), every TOML example parses (as a scene, or as a bench ladder), and
//! `drape check` accepts every shipped scene and finds no pin of one that
//! differs from its region.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use drape::bench::Ladder;
use drape::scene::load_scene_str;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The documents whose commands and examples are checked.
fn documents() -> Vec<PathBuf> {
    let mut docs = vec![repo().join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(repo().join("docs"))
        .expect("docs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    docs
}

/// The fenced blocks of `lang` in `text`.
fn blocks(text: &str, lang: &str) -> Vec<String> {
    let open = format!("```{lang}");
    let mut out = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match &mut current {
            None if line.trim_end() == open => current = Some(String::new()),
            Some(b) if line.trim_start().starts_with("```") => {
                out.push(std::mem::take(b));
                current = None;
            }
            Some(b) => {
                b.push_str(line);
                b.push('\n');
            }
            None => {}
        }
    }
    out
}

/// A command line split into words as a POSIX shell would (quotes, no
/// expansion), without its trailing `# comment`.
fn words(line: &str) -> Vec<String> {
    let (mut out, mut word, mut quote, mut any) = (Vec::new(), String::new(), None, false);
    for c in line.chars() {
        match (quote, c) {
            (None, '#') if !any => break,
            (None, '\'' | '"') => (quote, any) = (Some(c), true),
            (Some(q), c) if c == q => quote = None,
            (None, c) if c.is_whitespace() => {
                if any {
                    out.push(std::mem::take(&mut word));
                }
                any = false;
            }
            (_, c) => (word, any) = (word + &c.to_string(), true),
        }
    }
    if any {
        out.push(word);
    }
    out
}

/// The drape arguments of a documented command line: after `drape`, or after
/// `cargo run --release --`; `None` for any other command.
fn drape_args(line: &str) -> Option<Vec<String>> {
    let w = words(line);
    match w.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["drape", ..] => Some(w[1..].to_vec()),
        ["cargo", "run", "--release", "--", ..] => Some(w[4..].to_vec()),
        _ => None,
    }
}

/// `args` with the option `name` and its value removed.
fn without(args: &[String], name: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut skip = false;
    for a in args {
        match (skip, a == name) {
            (true, _) => skip = false,
            (false, true) => skip = true,
            (false, false) => out.push(a.clone()),
        }
    }
    out
}

/// The brief form of a documented command, to run in `dir`.
fn brief(args: &[String], dir: &Path) -> Vec<String> {
    let s = |v: &[&str]| v.iter().map(|x| (*x).to_owned()).collect::<Vec<_>>();
    let mut a = args.to_vec();
    match a.first().map(String::as_str) {
        Some("run" | "garment") => {
            a = without(&without(&a, "--out"), "-o");
            a.extend(s(&[
                "--no-record",
                "-q",
                "--set",
                "simulation.duration=0.05",
            ]));
        }
        Some("bench") if a.get(1).is_some_and(|x| x == "collect") => a.clear(),
        // Collecting needs the jobs run; `garment_batch` runs one and collects.
        Some("garment-collect") => a.clear(),
        Some("bench") => {
            a = without(&a, "--out");
            if a.get(1).is_none_or(|x| x != "plan") {
                a.insert(1, "plan".into());
            }
            let out = dir.join(format!("plan-{}", a.len()));
            a.extend(["--out".to_owned(), out.display().to_string()]);
        }
        Some("stability") => {
            a = without(&a, "--markdown");
            if !a.iter().any(|x| x == "--case") {
                a.extend(s(&["--case", "yank"]));
            }
            if !a.iter().any(|x| x == "--quick") {
                a.push("--quick".into());
            }
        }
        _ => {}
    }
    a
}

fn drape(args: &[String], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_drape"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("drape runs")
}

/// A working directory that looks like the repository root (`scenes/`,
/// `docs/` and `src/`, which holds the default scene's file, linked), holding the docs' example scenes under their names and a
/// short recording `default.rrd` for the `inspect` examples.
fn workdir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("drape-docs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    for d in ["scenes", "docs", "src"] {
        std::os::unix::fs::symlink(repo().join(d), dir.join(d)).expect("link");
    }
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).expect("doc");
        for b in blocks(&text, "toml") {
            if let Ok(scene) = load_scene_str(&b, "example", &[]) {
                std::fs::write(dir.join(format!("{}.toml", scene.name)), &b).expect("saved");
            }
        }
    }
    let set = [
        "run",
        "--set",
        "simulation.duration=0.1",
        "-q",
        "--out",
        "default.rrd",
    ];
    let out = drape(&set.map(String::from), &dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

#[test]
fn every_documented_command_runs() {
    let dir = workdir();
    let mut ran = 0;
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).expect("doc");
        for block in blocks(&text, "sh") {
            for line in block.lines() {
                let Some(args) = drape_args(line) else {
                    continue;
                };
                let args = brief(&args, &dir);
                if args.is_empty() {
                    continue;
                }
                let out = drape(&args, &dir);
                assert!(
                    out.status.success(),
                    "{}: `{line}` (run as drape {args:?}) failed: {}",
                    doc.display(),
                    String::from_utf8_lossy(&out.stderr)
                );
                ran += 1;
            }
        }
    }
    assert!(ran >= 10, "only {ran} documented commands found");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn every_documented_toml_example_parses() {
    let mut checked = 0;
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).expect("doc");
        for (i, block) in blocks(&text, "toml").iter().enumerate() {
            let origin = format!("{} toml block {}", doc.display(), i + 1);
            if block.contains("[[rung]]") {
                Ladder::parse(block).unwrap_or_else(|e| panic!("{origin}: {e}"));
            } else {
                load_scene_str(block, &origin, &[]).unwrap_or_else(|e| panic!("{e}"));
            }
            checked += 1;
        }
    }
    assert!(checked >= 3, "only {checked} TOML examples found");
}

/// Every scene file under `scenes/` and `scenes/hard/`.
fn shipped_scenes() -> Vec<PathBuf> {
    let mut scenes = Vec::new();
    for dir in ["scenes", "scenes/hard"] {
        for e in std::fs::read_dir(repo().join(dir)).expect("scenes") {
            let p = e.expect("entry").path();
            if p.extension().is_some_and(|x| x == "toml") {
                scenes.push(p);
            }
        }
    }
    scenes.sort();
    assert!(scenes.len() >= 15, "{scenes:?}");
    scenes
}

#[test]
fn drape_check_accepts_every_shipped_scene() {
    for scene in shipped_scenes() {
        let args = ["check".to_owned(), scene.display().to_string()];
        let out = drape(&args, &repo());
        assert!(
            out.status.success(),
            "{}: {}",
            scene.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// No shipped scene warns about its own setup: every pin holds the region
/// it names (`drape check` prints `differs from the scene` under a pin whose
/// held vertices are not the cloth inside its box or disk).
#[test]
fn no_shipped_scene_warns_about_its_own_setup() {
    let mut warned = Vec::new();
    for scene in shipped_scenes() {
        let args = ["check".to_owned(), scene.display().to_string()];
        let out = drape(&args, &repo());
        let text = String::from_utf8_lossy(&out.stdout);
        for line in text
            .lines()
            .filter(|l| l.contains("differs from the scene"))
        {
            warned.push(format!("{}: {}", scene.display(), line.trim()));
        }
    }
    assert!(warned.is_empty(), "{}", warned.join("\n"));
}
