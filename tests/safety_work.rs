//! Issue 40 item 6: limits sized by the work an input asks for, each checked before the
//! work starts (exit 2, the limit's constant, the amount asked and the options that set it
//! named, nothing written): `equilibrium` contacts × COM states, `edit run` output frames
//! × joints, a pipeline's `inputs` globs (repeats expanded once).

use crate::safety_caps::{ring, write_points};
use crate::util::{fixture_clips, fixture_library, ok, refused, root, s};

use stancelib::edit::MAX_EDIT_FRAME_JOINTS;
use stancelib::pipeline::spec::MAX_INPUT_PATTERNS;
use stancelib::twopac::equilibrium::MAX_CONTACT_STATES;

fn contacts_file(n: usize) -> String {
    format!(
        r#"{{"schema": "stancelib.twopac.contacts/1", "mass_kg": 54, "contacts": [{}]}}"#,
        ring(n)
    )
}

// See: issue 40 item 6 — `equilibrium` with 64 contacts × 20,000 points was still
// running at 300 s (each contact and state is one share of an LP).
#[test]
fn issue40_item6_equilibrium_contacts_times_points_beyond_max_contact_states_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (contacts, points) = (dir.path().join("c.json"), dir.path().join("p.parquet"));
    let out = dir.path().join("r.parquet");
    std::fs::write(&contacts, contacts_file(64)).unwrap();
    write_points(&points, 20_000);
    const { assert!(64 * 20_000 > MAX_CONTACT_STATES) };
    let args = [
        "equilibrium",
        "--contacts",
        &s(&contacts),
        "--points",
        &s(&points),
        "--out",
        &s(&out),
    ];
    let t0 = std::time::Instant::now();
    refused(
        &args,
        &[
            "--points (20000 rows) × --contacts (64 contacts)",
            "1280000 contact-states",
            &MAX_CONTACT_STATES.to_string(),
            "MAX_CONTACT_STATES",
        ],
    );
    // Refused before any LP: one LP of 64 contacts takes about 10 ms.
    assert!(t0.elapsed().as_secs_f64() < 60.0);
    assert!(!out.exists());

    // The `--png` slice's cells count as states: 10,000 rows alone are within the limit,
    // with the slice's 6,400 cells they are not.
    write_points(&points, 10_000);
    let png = dir.path().join("r.png");
    let mut with_png = args.to_vec();
    let png_s = s(&png);
    with_png.extend(["--png", &png_s]);
    refused(
        &with_png,
        &["+ 6400 cells of the --png slice", "MAX_CONTACT_STATES"],
    );
    assert!(!out.exists() && !png.exists());
}

// See: issue 40 item 6 — `edit run --cycles 1000 --fps 1000` wrote an 871 MB BVH with
// 2.6 GB of memory.
#[test]
fn issue40_item6_edit_run_frames_times_joints_beyond_the_limit_is_refused_before_posing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run.bvh");
    let lib = s(fixture_library());
    // The library records its clips' paths relative to the repository.
    let run = |cycles: &str, fps: Option<&str>| {
        let mut a = vec![
            "edit", "run", "--lib", &lib, "--speed", "3.5", "--cycles", cycles,
        ];
        if let Some(f) = fps {
            a.extend(["--fps", f]);
        }
        let o = s(&out);
        let mut v: Vec<String> = a.iter().map(|x| x.to_string()).collect();
        v.extend(["--out".to_string(), o]);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_stancelib"))
            .args(&v)
            .current_dir(root())
            .output()
            .unwrap();
        (
            o.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let t0 = std::time::Instant::now();
    let (code, _, err) = run("1000", Some("1000"));
    assert_eq!(code, 2, "{err}");
    for needle in [
        "--cycles",
        "--fps",
        "1000.0 Hz",
        "frame-joints",
        "MAX_EDIT_FRAME_JOINTS",
        &MAX_EDIT_FRAME_JOINTS.to_string(),
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    // Refused before posing: 100 cycles at 1000 Hz take about 1.5 s to pose.
    assert!(t0.elapsed().as_secs_f64() < 30.0);
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());

    // The largest edit a fixture run at its own rate asks for stays within the limit.
    let (code, printed, err) = run("1000", None);
    assert_eq!(code, 0, "{err}");
    // "edit: 88000 frame(s) at 120.0 Hz → …"
    let frames: f64 = printed
        .split("edit: ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no frame count in {printed}"));
    assert!(frames > 10_000.0, "{printed}");
    assert!(out.is_file());
}

/// A pipeline file at `dir/p.toml` whose inputs repeat `glob` `n` times.
fn repeated_inputs(dir: &std::path::Path, glob: &str, n: usize) -> std::path::PathBuf {
    let p = dir.join("p.toml");
    let list = vec![format!("{glob:?}"); n].join(", ");
    std::fs::write(&p, format!("inputs = [{list}]\nout = \"lib\"\n")).unwrap();
    p
}

// See: issue 40 item 6 — a pipeline whose `inputs` repeats a glob 10⁶ times held 723 MB
// and was still expanding after 60 s.
#[test]
fn issue40_item6_pipeline_inputs_beyond_max_input_patterns_refused_and_repeats_expanded_once() {
    let dir = tempfile::tempdir().unwrap();
    let clips = dir.path().join("clips");
    std::fs::create_dir(&clips).unwrap();
    for c in &fixture_clips()[..2] {
        let name = std::path::Path::new(c).file_name().unwrap();
        std::fs::copy(c, clips.join(name)).unwrap();
    }
    // Within the TOML size bound (1 MiB), beyond the glob count.
    let n = MAX_INPUT_PATTERNS + 1;
    let p = repeated_inputs(dir.path(), "clips/*.bvh", n);
    refused(
        &["run", &s(&p)],
        &[
            "p.toml:1:",
            "inputs",
            &format!("{n} globs"),
            "MAX_INPUT_PATTERNS",
        ],
    );
    assert!(!dir.path().join("lib").exists());

    // At the limit, the repeats are expanded once: two clips, not 2 × 10,000.
    let p = repeated_inputs(dir.path(), "clips/*.bvh", MAX_INPUT_PATTERNS);
    let t0 = std::time::Instant::now();
    let printed = ok(&["run", &s(&p)]);
    assert!(printed.contains("2 clips"), "{printed}");
    assert!(t0.elapsed().as_secs_f64() < 60.0);
}
