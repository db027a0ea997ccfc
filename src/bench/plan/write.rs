//! Writing a plan into its bench directory: the scene and the files it
//! names, the sample points, the plan and the job list.

use std::path::{Path, PathBuf};

use super::super::BenchError;
use super::super::sampling::{SamplePoints, write_json};
use super::{JOBS_FILE, Job, PLAN_FILE, POINTS_FILE, Plan, load};

/// FNV-1a, 64 bits: a hash that is the same on every platform and version.
pub fn fnv1a(parts: &[&str]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for b in part.bytes().chain([0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// Writes `plan` into `dir`: the scene and its files, the points, the plan
/// and the job list. `DIR/out/` is emptied; the reference is taken from
/// `DIR/cache/` when `cache` allows and it is there. Returns the plan as written.
pub fn write_plan(
    mut plan: Plan,
    points: &SamplePoints,
    scene: &Path,
    dir: &Path,
    cache: bool,
) -> Result<Plan, BenchError> {
    prepare_dir(dir)?;
    let (scene_file, files) = copy_scene(scene, dir)?;
    plan.scene_file = scene_file;
    let scene_text = std::fs::read_to_string(scene).map_err(|e| BenchError::io(scene, e))?;
    let grid = serde_json::to_string(&points.points).unwrap_or_default();
    let mut parts: Vec<&str> = vec![&scene_text, env!("CARGO_PKG_VERSION"), &grid, &files];
    parts.extend(plan.reference.set.iter().map(String::as_str));
    let key = format!("{:016x}", fnv1a(&parts));
    plan.reference_output = match cache {
        true => format!("cache/{}-{key}.json", plan.scene),
        false => "out/reference.json".to_owned(),
    };
    plan.jobs.clear();
    if !(cache && dir.join(&plan.reference_output).is_file()) {
        let output = plan.reference_output.clone();
        plan.jobs.push(Job {
            run: None,
            rep: 1,
            output,
        });
    }
    for rep in 1..=plan.reps {
        for i in 0..plan.runs.len() {
            // A floor is compared, not timed: one repetition.
            if rep > 1 && plan.runs[i].floor {
                continue;
            }
            let output = format!("out/{:03}-{}-r{rep}.json", i + 1, slug(&plan.runs[i].label));
            plan.jobs.push(Job {
                run: Some(i),
                rep,
                output,
            });
        }
    }
    write_json(&dir.join(POINTS_FILE), points)?;
    write_json(&dir.join(PLAN_FILE), &plan)?;
    let jobs: String = plan
        .jobs
        .iter()
        .map(|j| format!("drape {}\n", shell_words(&plan.argv(j))))
        .collect();
    let path = dir.join(JOBS_FILE);
    std::fs::write(&path, jobs).map_err(|e| BenchError::io(&path, e))?;
    Ok(plan)
}

/// Creates `dir`, or checks that an existing one is a bench directory (or
/// empty), and empties its `out/`.
fn prepare_dir(dir: &Path) -> Result<(), BenchError> {
    let existing = std::fs::read_dir(dir).ok().map(|mut d| d.next().is_some());
    if existing == Some(true) && !dir.join(PLAN_FILE).is_file() {
        return Err(BenchError::Plan(format!(
            "{} exists and is not a bench directory (it has no {PLAN_FILE}); give an empty or new directory",
            dir.display()
        )));
    }
    let out = dir.join("out");
    if out.is_dir() {
        std::fs::remove_dir_all(&out).map_err(|e| BenchError::io(&out, e))?;
    }
    std::fs::create_dir_all(&out).map_err(|e| BenchError::io(&out, e))
}

/// Copies the scene file and the OBJ files it names into `DIR/scene/`, keeping
/// their places relative to each other; returns the scene's path relative to
/// `dir` and the copied files' names (for the cache key).
fn copy_scene(scene_path: &Path, dir: &Path) -> Result<(String, String), BenchError> {
    let scene = load(scene_path, &[], "scene")?;
    let canon = |p: &Path| std::fs::canonicalize(p).map_err(|e| BenchError::io(p, e));
    let mut sources = vec![canon(scene_path)?];
    let names = scene.obstacle.iter().filter_map(|o| o.path.as_deref());
    for p in scene.cloth.path.as_deref().into_iter().chain(names) {
        sources.push(canon(Path::new(p))?);
    }
    let mut root: PathBuf = sources[0]
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    while !sources.iter().all(|s| s.starts_with(&root)) {
        if !root.pop() {
            break;
        }
    }
    let mut relative = Vec::new();
    for s in &sources {
        let inside = s.strip_prefix(&root).map_err(|_| {
            BenchError::Plan(format!(
                "{} and the scene file have no common folder to copy them from",
                s.display()
            ))
        })?;
        let rel = Path::new("scene").join(inside);
        let to = dir.join(&rel);
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).map_err(|e| BenchError::io(parent, e))?;
        }
        std::fs::copy(s, &to).map_err(|e| BenchError::io(s, e))?;
        relative.push(rel.to_string_lossy().replace('\\', "/"));
    }
    let files = relative[1..].join("\n");
    Ok((relative.swap_remove(0), files))
}

/// A label as a file-name part: letters, digits, `.` and `-`.
fn slug(label: &str) -> String {
    let s: String = label
        .chars()
        .map(|c| match c.is_ascii_alphanumeric() || c == '.' {
            true => c,
            false => '-',
        })
        .collect();
    s.trim_matches('-').to_owned()
}

/// The arguments as one POSIX shell command line (single-quoted where needed).
pub fn shell_words(argv: &[String]) -> String {
    let quote = |a: &String| {
        let plain = |c: char| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c);
        match !a.is_empty() && a.chars().all(plain) {
            true => a.clone(),
            false => format!("'{}'", a.replace('\'', r"'\''")),
        }
    };
    argv.iter().map(quote).collect::<Vec<_>>().join(" ")
}
