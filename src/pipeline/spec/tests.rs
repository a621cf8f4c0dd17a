use super::*;

#[test]
fn unknown_keys_and_bad_values_name_the_line() {
    let p = Path::new("x.toml");
    let e = parse_pipeline(p, "inputs = [\"a\"]\nout = \"o\"\nbogus = 1\n")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("x.toml:3:"), "{e}");
    let e = parse_pipeline(p, "inputs = [\"a\"]\nout = \"o\"\nup_axis = \"up\"\n")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("x.toml:3:") && e.contains("up_axis"), "{e}");
    let e = parse_body(p, "mass_kg = 70\nunit = \"furlong\"\n")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("x.toml:2:"), "{e}");
}

fn pipeline_error(extra: &str) -> String {
    let text = format!("inputs = [\"a\"]\nout = \"o\"\n{extra}");
    parse_pipeline(Path::new("x.toml"), &text)
        .unwrap_err()
        .to_string()
}

// See: issue 11 item 10 — every value range-checked (`[constraints] mu = -1` was
// accepted) and keys without effect refused, each at its line.
#[test]
fn values_are_range_checked_at_their_line() {
    let q = "[queries]\nrun_speeds = \"0:6:0.5\"\n";
    for (extra, line, needle) in [
        (
            format!("[constraints]\nmu = -1\n{q}"),
            4,
            "[constraints] mu",
        ),
        (
            format!("[constraints]\nmu = nan\n{q}"),
            4,
            "[constraints] mu",
        ),
        (
            "[constraints]\nmu = 0.5\n".to_string(),
            4,
            "no [queries] stage",
        ),
        ("threads = 1000000\n".to_string(), 3, "MAX_THREADS_PER_CORE"),
        (
            "layout = \"hive\"\n".to_string(),
            3,
            "layout must be file or dataset",
        ),
        (
            "[contacts]\nfloor_window_s = 0\n".to_string(),
            4,
            "floor_window_s",
        ),
        ("[contacts]\nfoot_v_off = -2\n".to_string(), 4, "foot_v_off"),
        (
            "[queries]\nrun_speeds = \"0:6:0\"\n".to_string(),
            4,
            "run_speeds",
        ),
        ("[queries]\nrun_speeds = \"-1:6:1\"\n".to_string(), 4, "≥ 0"),
        (format!("{q}mass_scale = 0\n"), 5, "mass_scale"),
        (
            "[queries]\nmass_scale = 2\n".to_string(),
            4,
            "without run_speeds",
        ),
        (
            "[queries]\njump_map = true\nmap_heights = \"0:1:1e-9\"\n".to_string(),
            5,
            "MAX_AXIS_VALUES",
        ),
        (
            "[queries]\njump_map = false\nmap_heights = \"0:1:0.1\"\n".to_string(),
            5,
            "jump_map = true",
        ),
        ("[fit]\nsamples = 1\n".to_string(), 4, "MAX_SAMPLES"),
    ] {
        let e = pipeline_error(&extra);
        assert!(e.starts_with(&format!("x.toml:{line}: ")), "{extra}: {e}");
        assert!(e.contains(needle), "{extra}: {e}");
    }
    let p = Path::new("x.toml");
    let good =
        "inputs = [\"a\"]\nout = \"o\"\n[constraints]\nmu = 0.3\n[queries]\njump_map = true\n";
    assert_eq!(
        parse_pipeline(p, good).unwrap().constraints.unwrap().mu,
        Some(0.3)
    );
}

// See: issue 11 item 12 — duplicate TOML keys: the toml crate refuses them.
#[test]
fn duplicate_keys_are_refused_at_their_line() {
    let e = pipeline_error("threads = 1\nthreads = 2\n");
    assert!(
        e.starts_with("x.toml:4: ") && e.contains("duplicate key"),
        "{e}"
    );
    let e = parse_body(Path::new("b.toml"), "mass_kg = 70\nmass_kg = 80\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("b.toml:2: ") && e.contains("duplicate key"),
        "{e}"
    );
}

#[test]
fn relative_paths_fold_dot_dot() {
    let p = Path::new("pipelines/demo.toml");
    assert_eq!(relative_to(p, "../out/demo"), PathBuf::from("out/demo"));
    assert_eq!(
        relative_to(p, "../../elsewhere/x"),
        PathBuf::from("../elsewhere/x")
    );
    assert_eq!(
        relative_to(Path::new("demo.toml"), "out"),
        PathBuf::from("out")
    );
}

#[test]
fn precedence_is_cli_pipeline_body_default() {
    let body = parse_body(
        Path::new("b"),
        "mass_kg = 80\nunit = \"cm\"\nsex = \"female\"\n",
    )
    .unwrap();
    let pipe = parse_pipeline(
        Path::new("p"),
        "inputs = [\"a\"]\nout = \"o\"\nmass_kg = 75\n[contacts]\nfoot_h_on = 0.03\n",
    )
    .unwrap();
    let o = resolve(Some(&body), Some(&pipe), &Overrides::default());
    assert_eq!(
        (o.mass_kg, o.unit_m, o.sex, o.contacts.foot.h_on),
        (75.0, Some(0.01), Sex::Female, 0.03)
    );
    let o = resolve(
        Some(&body),
        Some(&pipe),
        &Overrides {
            mass_kg: Some(60.0),
            ..Default::default()
        },
    );
    assert_eq!(o.mass_kg, 60.0);
    assert_eq!(resolve(None, None, &Overrides::default()).mass_kg, 70.0);
}
