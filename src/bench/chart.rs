//! The benchmark's chart, hand-written SVG: mean error against wall time on
//! log-log axes, uniform runs as blue circles, adaptive runs as orange
//! squares, the Pareto front as a line through ringed points; points are
//! numbered, with the key of numbers to labels on the right.

use std::fmt::Write as _;

use super::Row;

const W: f64 = 820.0;
const H: f64 = 500.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 260.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 60.0;

/// A log10 axis spanning whole decades around the data.
#[derive(Debug, Clone, Copy)]
struct Axis {
    lo: f64,
    hi: f64,
}

impl Axis {
    fn around(values: impl Iterator<Item = f64>) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values.filter(|v| v.is_finite() && *v > 0.0) {
            lo = lo.min(v.log10());
            hi = hi.max(v.log10());
        }
        if !lo.is_finite() {
            return Axis { lo: 0.0, hi: 1.0 };
        }
        let (lo, hi) = (lo.floor(), hi.ceil());
        Axis {
            lo,
            hi: if hi > lo { hi } else { lo + 1.0 },
        }
    }

    /// Position of `v` in 0..1 along the axis.
    fn frac(&self, v: f64) -> f64 {
        (v.log10() - self.lo) / (self.hi - self.lo)
    }

    /// Tick values: 1, 2 and 5 times each power of ten in range.
    fn ticks(&self) -> Vec<(f64, bool)> {
        let mut out = Vec::new();
        for d in (self.lo as i32)..=(self.hi as i32) {
            for (m, major) in [(1.0, true), (2.0, false), (5.0, false)] {
                let v = m * 10f64.powi(d);
                if v.log10() <= self.hi + 1e-9 {
                    out.push((v, major));
                }
            }
        }
        out
    }
}

fn fmt_tick(v: f64) -> String {
    if (1e-3..1e4).contains(&v) {
        format!("{}", (v * 1e6).round() / 1e6)
    } else {
        format!("{v:.0e}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The chart of `rows` (wall time against mean error in percent) as SVG text.
pub fn svg(scene: &str, rows: &[Row]) -> String {
    let ok: Vec<&Row> = rows
        .iter()
        .filter(|r| r.wall_s.is_finite() && r.mean_error.is_finite() && r.mean_error > 0.0)
        .collect();
    let xa = Axis::around(ok.iter().map(|r| r.wall_s));
    let ya = Axis::around(ok.iter().map(|r| 100.0 * r.mean_error));
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let px = |v: f64| LEFT + pw * xa.frac(v);
    let py = |v: f64| TOP + ph * (1.0 - ya.frac(v));
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}: error against wall time</text>"#,
        LEFT + pw / 2.0,
        escape(scene)
    );
    for (v, major) in xa.ticks() {
        let x = px(v);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{TOP}" x2="{x:.1}" y2="{:.1}" stroke="{}"/>"##,
            TOP + ph,
            if major { "#ccc" } else { "#eee" }
        );
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            TOP + ph + 16.0,
            fmt_tick(v)
        );
    }
    for (v, major) in ya.ticks() {
        let y = py(v);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}"/>"##,
            LEFT + pw,
            if major { "#ccc" } else { "#eee" }
        );
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            LEFT - 6.0,
            y + 4.0,
            fmt_tick(v)
        );
    }
    let _ = writeln!(
        s,
        r#"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="black"/>"#
    );
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">wall time, s (median; log scale)</text>"#,
        LEFT + pw / 2.0,
        H - 18.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(20 {:.1}) rotate(-90)" text-anchor="middle">mean error, % of the diagonal (log scale)</text>"#,
        TOP + ph / 2.0
    );
    // The Pareto front: a staircase through its points in order of cost.
    let mut front: Vec<&&Row> = ok.iter().filter(|r| r.pareto).collect();
    front.sort_by(|a, b| a.wall_s.total_cmp(&b.wall_s));
    if !front.is_empty() {
        let mut d = String::new();
        for (i, r) in front.iter().enumerate() {
            let (x, y) = (px(r.wall_s), py(100.0 * r.mean_error));
            if i == 0 {
                let _ = write!(d, "M{x:.1},{y:.1}");
            } else {
                let _ = write!(d, " H{x:.1} V{y:.1}");
            }
        }
        let _ = writeln!(
            s,
            r#"<path d="{d}" fill="none" stroke="black" stroke-dasharray="5,3"/>"#
        );
    }
    for (n, r) in rows.iter().enumerate() {
        if !ok.iter().any(|o| std::ptr::eq(*o, r)) {
            continue;
        }
        let (x, y) = (px(r.wall_s), py(100.0 * r.mean_error));
        if r.pareto {
            let _ = writeln!(
                s,
                r#"<circle cx="{x:.1}" cy="{y:.1}" r="9" fill="none" stroke="black" stroke-width="1.5"/>"#
            );
        }
        if r.adaptive {
            let _ = writeln!(
                s,
                r##"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="#e67e22"/>"##,
                x - 4.5,
                y - 4.5
            );
        } else {
            let _ = writeln!(
                s,
                r##"<circle cx="{x:.1}" cy="{y:.1}" r="5" fill="#2e86de"/>"##
            );
        }
        let _ = writeln!(
            s,
            r##"<text x="{:.1}" y="{:.1}" font-size="10" fill="#333">{}</text>"##,
            x + 7.0,
            y - 5.0,
            n + 1
        );
    }
    legend(&mut s, rows.len() - ok.len());
    // The key of the point numbers.
    for (n, r) in rows.iter().enumerate() {
        let failed = if ok.iter().any(|o| std::ptr::eq(*o, r)) {
            ""
        } else {
            " (failed)"
        };
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="{:.1}" font-size="11">{} {}{failed}</text>"#,
            W - RIGHT + 20.0,
            TOP + 100.0 + 15.0 * n as f64,
            n + 1,
            escape(&r.label)
        );
    }
    s.push_str("</svg>\n");
    s
}

fn legend(s: &mut String, failed: usize) {
    let x = W - RIGHT + 20.0;
    let y = TOP + 10.0;
    let _ = writeln!(
        s,
        r##"<circle cx="{:.1}" cy="{y:.1}" r="5" fill="#2e86de"/><text x="{:.1}" y="{:.1}">uniform mesh</text>"##,
        x + 5.0,
        x + 16.0,
        y + 4.0
    );
    let _ = writeln!(
        s,
        r##"<rect x="{:.1}" y="{:.1}" width="9" height="9" fill="#e67e22"/><text x="{:.1}" y="{:.1}">adaptive</text>"##,
        x + 0.5,
        y + 15.5,
        x + 16.0,
        y + 24.0
    );
    let _ = writeln!(
        s,
        r#"<circle cx="{:.1}" cy="{:.1}" r="9" fill="none" stroke="black" stroke-width="1.5"/><text x="{:.1}" y="{:.1}">Pareto front</text>"#,
        x + 5.0,
        y + 40.0,
        x + 16.0,
        y + 44.0
    );
    if failed > 0 {
        let _ = writeln!(
            s,
            r#"<text x="{x:.1}" y="{:.1}">{failed} failed run(s) not shown</text>"#,
            y + 64.0
        );
    }
}
