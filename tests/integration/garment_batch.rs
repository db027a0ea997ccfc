//! `drape garment-plan` and `drape garment-collect`: a folder of patterns written as a
//! job list, one job run as a shell would run it, and the summaries gathered into a CSV.

use std::process::Command;

use crate::bad_input::{drape, temp_dir};

/// The repository's GarmentCode examples.
fn examples() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/garmentcode")
}

#[test]
fn a_pattern_folder_becomes_one_job_per_pattern_and_the_summaries_one_csv() {
    let dir = temp_dir("garment-batch");
    let patterns = dir.join("patterns");
    std::fs::create_dir_all(&patterns).expect("patterns dir");
    for name in ["hoody_mean", "shirt_mean"] {
        let file = format!("{name}_specification.json");
        std::fs::copy(examples().join(&file), patterns.join(&file)).expect("copy pattern");
    }
    let body = examples().join("mean_all.obj");
    let body = body.to_string_lossy();
    let plan = drape(
        &dir,
        &[
            "garment-plan",
            "patterns",
            "--body",
            &body,
            "--out",
            "jobs",
            "--set",
            "simulation.duration=0.05",
        ],
    );
    assert!(plan.status.success(), "{plan:?}");
    let jobs = std::fs::read_to_string(dir.join("jobs/jobs.txt")).expect("jobs.txt");
    let lines: Vec<&str> = jobs.lines().collect();
    assert_eq!(lines.len(), 2, "{jobs}");
    assert!(lines[0].starts_with("drape garment ") && lines[0].contains("hoody_mean"));
    assert!(
        lines[0].contains("--summary hoody_mean.json"),
        "{}",
        lines[0]
    );
    assert!(lines[1].contains("shirt_mean"), "{}", lines[1]);

    // Run the first job as GNU parallel would: its line in a shell, from the directory.
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_drape"));
    let path = format!(
        "{}:{}",
        bin.parent().expect("bin dir").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let ran = Command::new("sh")
        .arg("-c")
        .arg(lines[0])
        .current_dir(dir.join("jobs"))
        .env("PATH", path)
        .output()
        .expect("sh");
    assert!(ran.status.success(), "{ran:?}");

    // One job ran, one did not: the collector says so and exits 1.
    let collect = drape(&dir, &["garment-collect", "jobs"]);
    assert_eq!(collect.status.code(), Some(1), "{collect:?}");
    let csv = std::fs::read_to_string(dir.join("jobs/garments.csv")).expect("csv");
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert!(
        rows[0].starts_with("pattern,vertices,wall_s,at_rest"),
        "{csv}"
    );
    let hoody: Vec<&str> = rows[1].split(',').collect();
    assert_eq!(hoody[0], "hoody_mean");
    assert!(hoody[1].parse::<f64>().expect("vertices") > 1000.0, "{csv}");
    assert!(hoody[2].parse::<f64>().expect("wall") > 0.0, "{csv}");
    assert_eq!(hoody[6], "12", "the hoody's 12 stitches: {csv}");
    assert_eq!(hoody.last(), Some(&"ok"));
    assert!(
        rows[2].starts_with("shirt_mean,") && rows[2].ends_with(",missing"),
        "{csv}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A job killed before it ends (by `timeout`, say) leaves its summary file
/// empty: the collector writes the table with that job `empty` and exits 1,
/// rather than stopping at the file.
#[test]
fn an_empty_summary_of_a_killed_job_collects_as_empty() {
    let dir = temp_dir("garment-batch-empty");
    let patterns = dir.join("patterns");
    std::fs::create_dir_all(&patterns).expect("patterns dir");
    for name in ["hoody_mean", "shirt_mean"] {
        let file = format!("{name}_specification.json");
        std::fs::copy(examples().join(&file), patterns.join(&file)).expect("copy pattern");
    }
    let body = examples().join("mean_all.obj");
    let plan = drape(
        &dir,
        &[
            "garment-plan",
            "patterns",
            "--body",
            &body.to_string_lossy(),
            "--out",
            "jobs",
        ],
    );
    assert!(plan.status.success(), "{plan:?}");
    std::fs::write(dir.join("jobs/hoody_mean.json"), "").expect("empty summary");
    let collect = drape(&dir, &["garment-collect", "jobs"]);
    assert_eq!(collect.status.code(), Some(1), "{collect:?}");
    let csv = std::fs::read_to_string(dir.join("jobs/garments.csv")).expect("csv");
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(rows.len(), 3, "{csv}");
    assert_eq!(rows[1], "hoody_mean,,,,,,,,,empty", "{csv}");
    assert_eq!(rows[2], "shirt_mean,,,,,,,,,missing", "{csv}");
    std::fs::remove_dir_all(&dir).ok();
}
