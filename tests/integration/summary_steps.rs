//! The summary's step count and step size add up to the simulated time: a
//! steady step prints one size, a varying one its range and its mean, and the
//! count printed is of the steps the time is made of.

use drape::summary::Summary;

/// A 1 m sheet at 8 segments hanging from its top edge for 0.3 s.
const HANGING: &str = r#"name = "hanging"
[simulation]
duration = 0.3
integrator = "implicit"
[cloth]
shape = "rectangle"
width = 1.0
height = 1.0
resolution = 8
[material]
density = 0.15
stretch = 200.0
bending = 1.0e-5
[[pin]]
region = "edge:top"
"#;

/// The hanging sheet's run summary with `simulation.dt` set to `dt`.
fn summary(dt: &str) -> Summary {
    let set = format!("simulation.dt={dt}");
    crate::adaptive_dt::summary(HANGING, &[set.as_str()])
}

/// The numbers of the paragraph's step clause, from `frames, ` to `to t = T s`:
/// the count, the sizes printed (one, or the smallest, largest and mean) and T.
fn step_clause(paragraph: &str) -> (u64, Vec<f64>, f64) {
    let start = paragraph.find(" frames, ").expect("frames") + " frames, ".len();
    let end = paragraph[start..].find(" s in ").expect("wall time") + start;
    let clause = &paragraph[start..end];
    println!("step clause: {clause}");
    let words: Vec<&str> = clause.split([' ', '(', ')', ';']).collect();
    let count = words[0].parse().expect("step count");
    let numbers: Vec<f64> = words.iter().filter_map(|w| w.parse().ok()).collect();
    let time = *numbers.last().expect("t");
    let sizes = numbers[1..numbers.len() - 1].to_vec();
    (count, sizes, time)
}

/// `{:.3e}` keeps four significant digits: a relative rounding of 5e-4.
const PRINTED: f64 = 5e-4;

#[test]
fn a_varying_step_prints_its_range_and_a_mean_that_adds_up_to_the_time() {
    let s = summary("\"adaptive\"");
    let text = s.paragraph();
    assert!(s.step_varied(), "{text}");
    let (count, sizes, time) = step_clause(&text);
    let [smallest, largest, mean] = sizes[..3] else {
        panic!("no range and mean in {text}");
    };
    assert!(text.contains(&format!("{count} steps of ")), "{text}");
    assert!(text.contains("(mean "), "{text}");
    assert_eq!(count, s.stepping.steps_accepted);
    assert!(smallest <= mean && mean <= largest, "{text}");
    assert!(largest > smallest * 1.01, "{text}");
    let total = count as f64 * mean;
    assert!(
        (total - time).abs() <= PRINTED * time,
        "{count} x {mean} = {total} s, not {time} s"
    );
    assert!(
        (s.stepping.dt_mean * s.stepping.steps_accepted as f64 - s.extent.sim_time).abs() < 1e-9
    );
    assert!((s.stepping.dt_max - largest).abs() <= PRINTED * largest);
}

#[test]
fn a_steady_step_prints_one_size_whose_count_adds_up_to_the_time() {
    // 1 ms steps evened out to 34 of 0.9804 ms a frame: steady.
    let s = summary("0.001");
    let text = s.paragraph();
    assert!(!s.step_varied(), "{text}");
    let (count, sizes, time) = step_clause(&text);
    assert_eq!(sizes.len(), 1, "{text}");
    assert_eq!(count, s.extent.steps);
    assert_eq!(count, s.stepping.steps_accepted);
    assert!(!text.contains("(mean "), "{text}");
    let total = count as f64 * sizes[0];
    assert!(
        (total - time).abs() <= PRINTED * time,
        "{count} x {} = {total} s, not {time} s",
        sizes[0]
    );
}
