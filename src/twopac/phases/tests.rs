use super::*;

const HEAD: &str = r#""schema": "stancelib.twopac.phases/1", "mass_kg": 60,"#;

fn one_phase(contact: &str, kin: &str) -> String {
    format!(
        r#"{{{HEAD} "effectors": {{"e": {{"kinematics": {kin}}}}},
               "phases": [{{"com": [0, 0, 1], "contacts": [{contact}]}}]}}"#
    )
}

/// A box `x ∈ [−0.1, 0.3]`, `y ∈ [−0.2, 0.2]`, `z ∈ [0, 1]` in the effector frame.
const BOX: &str =
    r#"{"A": [[1,0,0],[-1,0,0],[0,1,0],[0,-1,0],[0,0,1],[0,0,-1]], "b": [0.3,0.1,0.2,0.2,1,0]}"#;

fn world(contact: &str) -> Polytope {
    let f = parse_phases(&one_phase(contact, BOX)).unwrap();
    let none = |_: &str| None;
    f.to_phases(&none).unwrap()[0].kinematics[0].clone()
}

#[test]
fn yawed_foot_turns_its_box_about_z() {
    // yaw 90°: the frame's x is world +Y, so the box's long side [−0.1, 0.3] runs
    // along world y from the position (1, 2, 0). 1e-12 m: round-off of sin/cos.
    let k = world(
        r#"{"effector": "e", "position": [1, 2, 0], "normal": [0, 0, 1], "yaw_rad": 1.5707963267948966}"#,
    );
    assert!(k.contains([1.0, 2.29, 0.5], 1e-12));
    assert!(!k.contains([1.0, 2.31, 0.5], 1e-12));
    assert!(k.contains([1.19, 1.91, 0.5], 1e-12));
    assert!(!k.contains([1.21, 2.0, 0.5], 1e-12));
}

#[test]
fn wall_contact_keeps_z_up_in_its_kinematic_frame() {
    // Normal −X: §1.1 frame x is the projection of +Y, i.e. world +Y; the kinematic
    // frame is yaw-only with z up (§3), yaw 90°, so z stays the box's z.
    let c = r#"{"effector": "e", "position": [0.5, 0, 1], "normal": [-1, 0, 0]}"#;
    let f = parse_phases(&one_phase(c, BOX)).unwrap();
    assert!((effector_yaw(&f.phases[0].contacts[0]) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    let k = world(c);
    assert!(k.contains([0.5, 0.29, 1.99], 1e-12));
    assert!(!k.contains([0.5, 0.0, 2.01], 1e-12));
    assert!(!k.contains([0.5, 0.0, 0.99], 1e-12));
}

#[test]
fn errors_carry_path_and_position() {
    let c = r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1], "surface": {"length_m": -1, "width_m": 0.1}}"#;
    let e = parse_phases(&one_phase(c, BOX)).unwrap_err();
    assert_eq!(e.path, "phases[0].contacts[0].surface.length_m");
    let c = r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1], "yaw_rad": "x"}"#;
    let e = parse_phases(&one_phase(c, BOX)).unwrap_err();
    assert_eq!(e.path, "phases[0].contacts[0].yaw_rad");
    assert_eq!(e.at.map(|a| a.0), Some(2));
    let e = parse_phases(&one_phase(
        r#"{"effector": "f", "position": [0, 0, 0], "normal": [0, 0, 1]}"#,
        BOX,
    ))
    .unwrap_err();
    assert_eq!(e.path, "phases[0].contacts[0].effector");
    let e = parse_phases(&one_phase(
        r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1]}"#,
        r#"{"A": [[1, 0, 0]], "b": [1, 2]}"#,
    ))
    .unwrap_err();
    assert_eq!(e.path, "effectors.e.kinematics");
    let e =
        parse_contacts(r#"{"schema": "stancelib.twopac.phases/1", "mass_kg": 1, "contacts": []}"#)
            .unwrap_err();
    assert_eq!(e.path, "schema");
}

// See: issue 11 item 12 — duplicate JSON keys were accepted (last wins).
#[test]
fn duplicate_keys_are_refused_at_their_path() {
    let c = r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1], "normal": [1, 0, 0]}"#;
    let e = parse_phases(&one_phase(c, BOX)).unwrap_err();
    assert_eq!(e.path, "phases[0].contacts[0].normal", "{e}");
    assert!(e.msg.contains("duplicate key"), "{e}");
    assert_eq!(e.at.map(|a| a.0), Some(2), "{e}");
    let e = parse_contacts(
        r#"{"schema": "stancelib.twopac.contacts/1", "schema": "x", "mass_kg": 1, "contacts": []}"#,
    )
    .unwrap_err();
    assert_eq!(e.path, "schema");
    // Equal keys in different objects are fine, and values keep their types.
    let ok = parse_phases(&one_phase(
        r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1], "friction": 0.5}"#,
        BOX,
    ))
    .unwrap();
    assert_eq!(ok.phases[0].contacts[0].mu, 0.5);
    assert_eq!(ok.mass_kg, 60.0);
}

// See: issue 11 item 6 — phases, contacts and the total duration are bounded.
#[test]
fn counts_beyond_the_limits_are_refused_at_their_path() {
    let c = r#"{"effector": "e", "position": [0, 0, 0], "normal": [0, 0, 1]}"#;
    let text = one_phase(c, BOX).replace(r#"{"com""#, r#"{"duration_s": 1e9, "com""#);
    let e = parse_phases(&text).unwrap_err();
    assert_eq!(e.path, "phases[0].duration_s");
    assert!(e.msg.contains("MAX_SAMPLES"), "{e}");
    let many = vec![c; MAX_CONTACTS + 1].join(", ");
    let e = parse_phases(&one_phase(&many, BOX)).unwrap_err();
    assert_eq!(e.path, "phases[0].contacts");
    assert!(e.msg.contains("MAX_CONTACTS"), "{e}");
    let phase = format!(r#"{{"com": [0, 0, 1], "contacts": [{c}]}}"#);
    let text = format!(
        r#"{{{HEAD} "effectors": {{"e": {{"kinematics": {BOX}}}}}, "phases": [{}]}}"#,
        vec![phase.as_str(); MAX_PHASES + 1].join(",")
    );
    let e = parse_phases(&text).unwrap_err();
    assert_eq!(e.path, "phases");
    assert!(e.msg.contains("MAX_PHASES"), "{e}");
}
