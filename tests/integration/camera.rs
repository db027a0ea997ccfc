//! The scene's `[camera]` table and the `angles` view's cloth, as a user sees them: a
//! scene run from the command line, its recording decoded with rerun's own reader.

use crate::cli::drape;
use crate::recording::decode;

/// A small falling sheet, two frames, with `camera` appended.
fn sheet_scene(camera: &str) -> String {
    format!(
        "name = \"cam\"\n[simulation]\nduration = 0.05\nframe_rate = 20\n\
         [cloth]\nshape = \"rectangle\"\nwidth = 1.0\nheight = 1.0\nresolution = 4\n\
         position = [0.0, 0.0, 1.0]\n[material]\ndensity = 0.1\nstretch = 100.0\n\
         bending = 1e-4\n{camera}"
    )
}

/// Runs `scene` in a fresh directory; returns the decoded recording.
fn run(name: &str, scene: &str) -> crate::recording::Decoded {
    let dir = std::env::temp_dir().join(format!("drape-camera-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(dir.join("cam.toml"), scene).expect("scene");
    let out = drape(&["run", "cam.toml", "--out", "cam.rrd"], &dir);
    assert!(out.status.success(), "drape run failed");
    let d = decode(&dir.join("cam.rrd"));
    std::fs::remove_dir_all(&dir).ok();
    d
}

#[test]
fn a_side_camera_places_both_eyes_behind_the_cloth_instead_of_tracking_it() {
    let d = run("back", &sheet_scene("[camera]\nside = \"back\"\n"));
    assert!(d.tracked.is_empty(), "no eye tracks: {:?}", d.tracked);
    assert_eq!(d.eye_positions.len(), 2, "{:?}", d.eye_positions);
    // The sheet spans [-0.5, 0.5]^2 at z = 1: its box's half diagonal is 0.707 m, so the
    // eye stands 2.12 m away towards +y and up (0, 1, 0.35) normalised.
    for p in &d.eye_positions {
        assert!(p.contains("2.00"), "y = 2.00 m: {p}");
        assert!(p.contains("1.70"), "z = 1.70 m: {p}");
    }
}

#[test]
fn an_eye_and_look_at_point_are_sent_as_given() {
    let d = run(
        "eye",
        &sheet_scene("[camera]\neye = [3.0, -4.0, 2.5]\nlook_at = [0.0, 0.0, 1.0]\n"),
    );
    assert_eq!(d.eye_positions.len(), 2, "{:?}", d.eye_positions);
    for p in &d.eye_positions {
        assert!(
            p.contains("3.0") && p.contains("-4.0") && p.contains("2.5"),
            "{p}"
        );
    }
}

#[test]
fn without_a_camera_both_eyes_follow_the_cloth() {
    let d = run("follow", &sheet_scene(""));
    assert_eq!(d.tracked.len(), 2, "{:?}", d.tracked);
    assert!(d.eye_positions.is_empty(), "{:?}", d.eye_positions);
}

#[test]
fn the_angles_view_draws_the_cloth_in_one_pale_colour() {
    let d = run("angles", &sheet_scene(""));
    let overrides: Vec<_> = d
        .colour_overrides
        .iter()
        .filter(|(entity, _)| entity.contains("/ViewContents/overrides/cloth/mesh/"))
        .collect();
    assert_eq!(overrides.len(), 1, "{:?}", d.colour_overrides);
    // 0xE4E4E4FF, rerun's packed RGBA.
    assert!(
        overrides[0].1.contains(&0xE4E4_E4FFu32.to_string()),
        "{overrides:?}"
    );
}

#[test]
fn a_camera_with_a_side_and_an_eye_is_refused_with_its_line() {
    let dir = std::env::temp_dir().join(format!("drape-camera-both-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let scene = sheet_scene("[camera]\nside = \"top\"\neye = [1.0, 1.0, 1.0]\n");
    std::fs::write(dir.join("cam.toml"), scene).expect("scene");
    let out = drape(&["check", "cam.toml"], &dir);
    std::fs::remove_dir_all(&dir).ok();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("cam.toml:17: key `camera.eye`"), "{err}");
    assert!(err.contains("not both"), "{err}");
}
