//! Column names of the output tables, in one place (spec com-from-bvh §8).
//!
//! `frames.parquet` (sorted by `clip`, `frame`): `clip`, `frame`, `time_s`, `com_{x,y,z}`,
//! `com_v{x,y,z}`, `com_a{x,y,z}`, `ground_z`, `contact_<e>`, `static_<e>`,
//! `surface_z_<e>`, `<e>_{x,y,z}`, `{left,right}_toe_{x,y,z}`.
//! `clips.parquet` (sorted by `clip`): see [`CLIPS_COLUMNS`].
//! `contacts.parquet` (sorted by `clip`, `effector`, `first_frame`): see [`CONTACTS_COLUMNS`].
//! `joints.parquet` (sorted by `clip`, `frame`, then file joint order): `clip`, `frame`,
//! `joint`, `x`, `y`, `z`.

/// Version of the table layout; bumped on any column change.
pub const SCHEMA_VERSION: &str = "3";
/// Per-frame table.
pub const FRAMES_FILE: &str = "frames.parquet";
/// Per-clip table.
pub const CLIPS_FILE: &str = "clips.parquet";
/// Contact-run table.
pub const CONTACTS_FILE: &str = "contacts.parquet";
/// Joint-position table (`--joints`).
pub const JOINTS_FILE: &str = "joints.parquet";
/// Stance table of a library.
pub const STANCES_FILE: &str = "stances.parquet";
/// Failed inputs and stages of a library.
pub const ERRORS_FILE: &str = "errors.parquet";
/// Reserved in the library layout for the kinematic polytopes of the multi-contact stage
/// (spec two-pac §3; not written yet).
pub const KINEMATICS_FILE: &str = "kinematics.parquet";
/// Points behind the kinematic polytopes (two-pac §3).
pub const KINEMATICS_POINTS_FILE: &str = "kinematics_points.parquet";
/// The kinematic summary of a shard library (`build --shard`): every contact frame's COM
/// in its contact frame before the outlier rules, from which `merge` makes the polytopes.
pub const KINEMATICS_SAMPLES_FILE: &str = "kinematics_samples.parquet";
/// Provenance of a library (JSON).
pub const MANIFEST_FILE: &str = "manifest.json";
/// Start of the manifest's `schema` value, `stancelib.library/<SCHEMA_VERSION>`: what makes
/// a folder a stancelib library, which `build` may replace.
pub const MANIFEST_SCHEMA_PREFIX: &str = "stancelib.library/";

/// Key-value metadata key of every library table: [`SCHEMA_VERSION`].
pub const SCHEMA_VERSION_KEY: &str = "stancelib.schema_version";
/// Key-value metadata key of every output: the tool version ([`TOOL_VERSION`]).
pub const TOOL_VERSION_KEY: &str = "stancelib.tool_version";
/// The tool version recorded everywhere (`CARGO_PKG_VERSION`).
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");
/// Key-value metadata key of a library table: the fingerprint of the build options.
pub const OPTIONS_KEY: &str = "stancelib.options";
/// Key-value metadata key of a library table: the inputs' content hashes (JSON).
pub const INPUTS_KEY: &str = "stancelib.inputs";
/// Key-value metadata key of a library table: the per-character limits (JSON).
pub const LIMITS_KEY: &str = "stancelib.limits";
/// Key-value metadata key of a query output: the query's options (JSON).
pub const QUERY_KEY: &str = "stancelib.query";
/// Key-value metadata key of an `equilibrium` output: its options (JSON).
pub const EQUILIBRIUM_KEY: &str = "stancelib.equilibrium";
/// Key-value metadata key of a `twopac` output: its options (JSON).
pub const TWOPAC_KEY: &str = "stancelib.twopac";
/// Key-value metadata key of a query output: SHA-256 (hex) of its library's
/// `manifest.json`.
pub const LIBRARY_MANIFEST_KEY: &str = "stancelib.library_manifest_sha256";
/// Key-value metadata key of a query output: the library folder as given.
pub const LIBRARY_PATH_KEY: &str = "stancelib.library";

/// The key-value metadata of a command's output: the tool version, then the command's
/// options as JSON under `key` (one of [`QUERY_KEY`], [`EQUILIBRIUM_KEY`], [`TWOPAC_KEY`]).
pub fn command_kv(key: &str, options: &serde_json::Value) -> Vec<(String, String)> {
    vec![
        (TOOL_VERSION_KEY.to_string(), TOOL_VERSION.to_string()),
        (key.to_string(), options.to_string()),
    ]
}

/// Columns of `clips.parquet`, in order.
pub const CLIPS_COLUMNS: [&str; 24] = [
    "path",
    "clip",
    "content_sha256",
    "status",
    "message",
    "frames_header",
    "frames_data",
    "frames_kept",
    "leadin_dropped",
    "frame_time_s",
    "unit_scale",
    "unit",
    "up_axis",
    "handedness_ok",
    "leg_length_m",
    "character_id",
    "mass_kg",
    "skeleton",
    "toe_tip_rule_left",
    "toe_tip_rule_right",
    "flights",
    "flight_az_median",
    "s_eff",
    "warnings",
];

/// Fields of the `flights` struct in `clips.parquet`.
pub const FLIGHT_FIELDS: [&str; 11] = [
    "first_frame",
    "last_frame",
    "duration_s",
    "a_z",
    "a_x",
    "a_y",
    "rms_m",
    "s_eff",
    "a_z_mean",
    "ballistic",
    "tested",
];

/// Columns of `contacts.parquet`, in order.
pub const CONTACTS_COLUMNS: [&str; 18] = [
    "clip",
    "effector",
    "first_frame",
    "last_frame",
    "t_td_s",
    "t_lo_s",
    "td_time_s",
    "lo_time_s",
    "static",
    "speed_led",
    "surface_z",
    "origin_x",
    "origin_y",
    "origin_z",
    "yaw_rad",
    "normal_x",
    "normal_y",
    "normal_z",
];

/// Columns of `stances.parquet`, in order (spec stance-model §11; written by
/// [`super::stances::stances_table`], read by [`super::stances::read_stances`]).
pub const STANCES_COLUMNS: [&str; 85] = [
    "stance_id",
    "clip",
    "character_id",
    "label",
    "effectors",
    "first_frame",
    "last_frame",
    "td_clip_s",
    "lo_clip_s",
    "t_td_s",
    "t_lo_s",
    "t_e_s",
    "dt_s",
    "boundary_start",
    "boundary_end",
    "rest_at_edge",
    "flight_before",
    "flight_after",
    "heading_x",
    "heading_y",
    "heading_from",
    "z_c",
    "zs",
    "vs",
    "ze",
    "ve",
    "vp",
    "x",
    "vps",
    "z_td",
    "z_lo",
    "ze_measured",
    "ve_measured",
    "vp_measured",
    "x_measured",
    "mass_kg",
    "c0_h",
    "c0_p",
    "c0_v",
    "harmonic_h",
    "harmonic_p",
    "harmonic_v",
    "amp_h",
    "amp_p",
    "amp_v",
    "phase_h",
    "phase_p",
    "phase_v",
    "fit_rms_h",
    "fit_rms_p",
    "fit_rms_v",
    "poly_h",
    "poly_p",
    "poly_v",
    "ratio_h",
    "ratio_p",
    "force_model",
    "j_h",
    "j_p",
    "j_v",
    "k_h",
    "k_p",
    "k_v",
    "s_bar_h",
    "s_bar_p",
    "s_bar_v",
    "support_ok",
    "unilateral_ok",
    "min_f_v",
    "a_f",
    "a_mu",
    "f_peak",
    "mu_req",
    "mu_req_robust",
    "ext_min",
    "ext_max",
    "cp_h",
    "cp_p",
    "ang_impulse",
    "ang_impulse_h0",
    "ell_r_min",
    "ell_r_max",
    "ell_s_min",
    "ell_s_max",
    "warnings",
];

/// Columns of `errors.parquet`, in order.
pub const ERRORS_COLUMNS: [&str; 4] = ["path", "clip", "stage", "message"];

/// Columns of `kinematics.parquet` (one row per facet), in order.
pub const KINEMATICS_COLUMNS: [&str; 6] = ["character_id", "effector", "nx", "ny", "nz", "d"];

/// Columns of `kinematics_points.parquet` and `kinematics_samples.parquet`, in order.
pub const KINEMATICS_POINTS_COLUMNS: [&str; 7] =
    ["character_id", "effector", "clip", "frame", "x", "y", "z"];
