//! Reading a benchmark's CSV back (for `drape bench --replot`, which redraws
//! the chart without running anything).

use std::path::Path;

use super::report::CSV_HEADER;
use super::{BenchError, Compare, Row};
use crate::math::Scalar;

/// Splits one CSV line into fields (double quotes quote, `""` is a quote).
pub fn split_csv_line(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                if let Some(f) = fields.last_mut() {
                    f.push('"');
                }
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            _ => {
                if let Some(f) = fields.last_mut() {
                    f.push(c);
                }
            }
        }
    }
    fields
}

/// Reads the rows of a CSV written by [`super::report::csv`] (the per-frame
/// errors are not in it and stay empty).
pub fn read_csv(path: &Path) -> Result<Vec<Row>, BenchError> {
    let text = std::fs::read_to_string(path).map_err(|source| BenchError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let bad = |message: String| BenchError::Ladder {
        path: path.to_path_buf(),
        message,
    };
    let mut lines = text.lines();
    if lines.next() != Some(CSV_HEADER) {
        return Err(bad("not a `drape bench` CSV (unexpected header)".into()));
    }
    let columns = CSV_HEADER.split(',').count();
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let f = split_csv_line(line);
        if f.len() != columns {
            return Err(bad(format!(
                "line {}: {} fields, expected {columns}",
                i + 2,
                f.len()
            )));
        }
        let num = |s: &str| s.parse::<Scalar>().unwrap_or(Scalar::NAN);
        let int = |s: &str| s.parse::<u64>().unwrap_or(0);
        rows.push(Row {
            label: f[0].clone(),
            adaptive: f[1] == "adaptive",
            method: f[2].clone(),
            resolution: int(&f[3]) as u32,
            finest_resolution: int(&f[4]) as u32,
            max_level: int(&f[5]) as u32,
            refine_angle: num(&f[6]),
            coarsen_angle: num(&f[7]),
            integrator: f[8].clone(),
            multirate: f[9] == "true",
            dt: f[10].clone(),
            status: f[11].clone(),
            reps: int(&f[12]) as usize,
            wall_s: num(&f[13]),
            walls: Vec::new(),
            steps: int(&f[14]),
            mean_vertices: num(&f[15]),
            peak_vertices: num(&f[16]),
            mean_error: num(&f[17]),
            final_error: num(&f[18]),
            final_offset: Scalar::NAN,
            compare: if f[19] == "rest" {
                Compare::Rest
            } else {
                Compare::Frames
            },
            error: num(&f[20]),
            pareto: f[21] == "true",
            set: f[22]
                .split(' ')
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect(),
            errors: Vec::new(),
            shadow_error: f64::NAN,
            sample_errors: Vec::new(),
        });
    }
    Ok(rows)
}

/// The larger sensitivity floor from `dir/stem-frames.csv` (its rows
/// labelled as [`super::floor::is_floor_label`] says), each compared as
/// `compare` says: `None` when the file or the rows are missing, or a floor
/// has no number ([`super::floor::largest_error`]).
pub fn floor_from_frames(dir: &Path, stem: &str, compare: super::Compare) -> Option<f64> {
    let text = std::fs::read_to_string(dir.join(format!("{stem}-frames.csv"))).ok()?;
    let mut by_label: Vec<(String, Vec<f64>)> = Vec::new();
    for f in text.lines().skip(1).map(split_csv_line) {
        if f.len() != 3 || !super::floor::is_floor_label(&f[0]) {
            continue;
        }
        let Ok(e) = f[2].parse() else { continue };
        match by_label.iter_mut().find(|(l, _)| *l == f[0]) {
            Some((_, v)) => v.push(e),
            None => by_label.push((f[0].clone(), vec![e])),
        }
    }
    super::floor::largest_error(by_label.into_iter().map(|(_, v)| compare.of(v.into_iter())))
}

/// Redraws `dir/stem.svg` from `dir/stem.csv` (`drape bench --replot`), with
/// the largest floor from `dir/stem-frames.csv` when it holds one;
/// returns the chart's path.
pub fn replot(dir: &Path, stem: &str) -> Result<std::path::PathBuf, BenchError> {
    let rows = read_csv(&dir.join(format!("{stem}.csv")))?;
    let svg = dir.join(format!("{stem}.svg"));
    let floor = rows
        .first()
        .and_then(|r| floor_from_frames(dir, stem, r.compare));
    std::fs::write(&svg, super::chart::svg(stem, &rows, floor)?).map_err(|source| {
        BenchError::Io {
            path: svg.clone(),
            source,
        }
    })?;
    Ok(svg)
}
