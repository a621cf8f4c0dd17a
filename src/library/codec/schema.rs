//! File names, metadata keys and column names of the library tables, each defined once:
//! the writers and the readers of a table use these constants.
//!
//! Naming rules (table layout 4):
//! - every physical quantity ends in its unit: `_m`, `_mps` (m/s), `_mps2` (m/s²), `_n` (N),
//!   `_n2` (N²), `_nms` (N·m·s), `_s`, `_rad`, `_kg`; dimensionless columns (ratios, μ,
//!   unit vectors, counts, flags) have none;
//! - an instant says which clock it is on: `_clip_s` is clip time (s from the file's first
//!   MOTION row, `frame · frame_time_s`), `_stance_s` is stance time (s from the stance's
//!   start apex, the paper's `t = 0`); a bare `_s` is a duration (`dt_s`, `duration_s`).
//!
//! Sort orders: `frames.parquet` by (`clip`, `frame`); `clips.parquet` by `clip`;
//! `contacts.parquet` by (`clip`, `effector`, `first_frame`); `joints.parquet` by (`clip`,
//! `frame`, file joint order); `stances.parquet` by (`clip`, `first_frame`, `label`).

/// Version of the table layout; bumped on any column change.
pub const SCHEMA_VERSION: &str = "4";
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

/// Key of `manifest.json` naming the library's layout (`file` or `dataset`,
/// [`crate::library::storage::layout::Layout`]); a manifest without it is a `file` library.
pub const LAYOUT_MANIFEST_KEY: &str = "layout";
/// The hive partition column of a `dataset` library's tables that have it.
pub const PARTITION_COLUMN: &str = "character_id";
/// The one data file of a partition (or of an unpartitioned table) of a `dataset` library.
pub const DATASET_PART_FILE: &str = "part-0.parquet";
/// The hive name of the partition of a null (or empty) value, as Hive and Spark write it
/// and DuckDB, polars, pyarrow and Spark read it (as null).
pub const HIVE_NULL_PARTITION: &str = "__HIVE_DEFAULT_PARTITION__";
/// Every table a library may hold, in the order `build` writes them.
pub const TABLE_FILES: [&str; 9] = [
    FRAMES_FILE,
    CONTACTS_FILE,
    CLIPS_FILE,
    STANCES_FILE,
    JOINTS_FILE,
    ERRORS_FILE,
    KINEMATICS_FILE,
    KINEMATICS_POINTS_FILE,
    KINEMATICS_SAMPLES_FILE,
];
/// The tables with a [`PARTITION_COLUMN`] (partitioned in a `dataset` library); the others
/// (`frames`, `contacts`, `joints`, `errors`) have no character column.
pub const PARTITIONED_FILES: [&str; 5] = [
    CLIPS_FILE,
    STANCES_FILE,
    KINEMATICS_FILE,
    KINEMATICS_POINTS_FILE,
    KINEMATICS_SAMPLES_FILE,
];

/// Sort keys of a table (the order a full build writes it, module docs); `errors.parquet`
/// and tables without keys of their own (`kinematics*.parquet` are written in
/// (`character_id`, `effector`) group order) get the errors keys.
pub fn sort_keys(file: &str) -> &'static [&'static str] {
    match file {
        // Joint rows keep the skeleton's order within a frame (the sort is stable).
        FRAMES_FILE | JOINTS_FILE => &[frames::CLIP, frames::FRAME],
        CONTACTS_FILE => &[contacts::CLIP, contacts::EFFECTOR, contacts::FIRST_FRAME],
        CLIPS_FILE => &[clips::CLIP],
        STANCES_FILE => &[stances::CLIP, stances::FIRST_FRAME, stances::LABEL],
        KINEMATICS_SAMPLES_FILE => &SAMPLES_SORT_KEYS,
        _ => &[errors::PATH, errors::STAGE, errors::MESSAGE],
    }
}

/// The columns whose every change ends a row group of a table (none: row groups of
/// `ROW_GROUP_ROWS` rows across the keys). Groups longer than `ROW_GROUP_ROWS` rows are cut
/// into groups of that many. The per-frame tables are cut per clip, so that a merge copies
/// a clip's groups from its shard without decoding them and still writes the bytes of a
/// single build; the polytopes' points per (character, effector), so that each group is
/// written on its own worker and its row groups put in order after. This is the `file`
/// layout's cut: the `dataset` layout rewrites the partitioned tables (`kinematics_points`
/// among them) in row groups of `ROW_GROUP_ROWS` rows.
pub fn group_keys(file: &str) -> &'static [&'static str] {
    match file {
        FRAMES_FILE | JOINTS_FILE => &[frames::CLIP],
        KINEMATICS_POINTS_FILE => &[kinematics::CHARACTER_ID, kinematics::EFFECTOR],
        _ => &[],
    }
}

/// The clip column of a table whose row groups each hold one clip ([`group_keys`]), which
/// a merge copies group by group from its shards.
pub fn group_column(file: &str) -> Option<&'static str> {
    match group_keys(file) {
        [c] if *c == frames::CLIP => Some(c),
        _ => None,
    }
}

/// Sort keys of `kinematics_samples.parquet` (and the order of `kinematics_points.parquet`).
pub const SAMPLES_SORT_KEYS: [&str; 4] = [
    kinematics::CHARACTER_ID,
    kinematics::EFFECTOR,
    kinematics::CLIP,
    kinematics::FRAME,
];

/// Nullable columns added to the layout after libraries of its [`SCHEMA_VERSION`] were
/// written: an older table without one reads as null (`Table::added_f64`) and an
/// incremental build over it fills it with nulls for the clips it keeps.
pub const ADDED_COLUMNS: [&str; 1] = [clips::REACH];

/// Key-value metadata key of every library table: [`SCHEMA_VERSION`].
pub const SCHEMA_VERSION_KEY: &str = "stancelib.schema_version";
/// Key-value metadata key of every output: the tool version ([`TOOL_VERSION`]).
pub const TOOL_VERSION_KEY: &str = "stancelib.tool_version";
/// The tool version recorded everywhere (`CARGO_PKG_VERSION`).
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");
/// SHA-256 (hex) of the source this build was compiled from (`src/`, `Cargo.toml`,
/// `Cargo.lock`; computed by `src/build.rs`). A library's manifest records it as
/// `source_digest`; `build --incremental` reuses rows only from a library of the same
/// source, because a change of the code changes rows that the options and the clip's
/// bytes do not name.
pub const SOURCE_DIGEST: &str = env!("STANCELIB_SOURCE_DIGEST");
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

/// Column names of `frames.parquet`: one row per kept frame.
pub mod frames {
    use crate::contacts::EFFECTORS;

    /// Axis suffixes of the position columns.
    const AXES: [&str; 3] = ["x", "y", "z"];
    /// `clip`: clip name.
    pub const CLIP: &str = "clip";
    /// `frame`: the file's MOTION row index.
    pub const FRAME: &str = "frame";
    /// `time_clip_s`: clip time of the frame, s.
    pub const TIME: &str = "time_clip_s";
    /// Whole-body COM, world frame (Z up), m.
    pub const COM: [&str; 3] = ["com_x_m", "com_y_m", "com_z_m"];
    /// COM velocity, m/s.
    pub const COM_V: [&str; 3] = ["com_vx_mps", "com_vy_mps", "com_vz_mps"];
    /// COM acceleration, m/s².
    pub const COM_A: [&str; 3] = ["com_ax_mps2", "com_ay_mps2", "com_az_mps2"];
    /// `ground_z_m`: the local floor height under the body, m.
    pub const GROUND_Z: &str = "ground_z_m";
    /// The toe points written besides the effectors (`<toe>_{x,y,z}_m`).
    pub const TOES: [&str; 2] = ["left_toe", "right_toe"];

    /// `contact_<e>`: effector `e` in contact (boolean).
    pub fn contact(e: &str) -> String {
        format!("contact_{e}")
    }

    /// `static_<e>`: effector `e`'s contact triggered by a static point (boolean, null
    /// without static detection).
    pub fn is_static(e: &str) -> String {
        format!("static_{e}")
    }

    /// `surface_z_<e>_m`: height of the surface under effector `e`, m.
    pub fn surface_z(e: &str) -> String {
        format!("surface_z_{e}_m")
    }

    /// `<point>_{x,y,z}_m`: world position of an effector (ankle or wrist) or toe, m.
    pub fn position(point: &str, axis: usize) -> String {
        format!("{point}_{}_m", AXES[axis])
    }

    /// Every column, in file order.
    pub fn columns() -> Vec<String> {
        let mut c: Vec<String> = [CLIP, FRAME, TIME].map(String::from).to_vec();
        c.extend(
            COM.iter()
                .chain(&COM_V)
                .chain(&COM_A)
                .map(|s| s.to_string()),
        );
        c.push(GROUND_Z.into());
        c.extend(EFFECTORS.iter().map(|e| contact(e)));
        for e in EFFECTORS {
            c.extend([is_static(e), surface_z(e)]);
        }
        for p in EFFECTORS.iter().chain(&TOES) {
            c.extend((0..3).map(|a| position(p, a)));
        }
        c
    }
}

/// Column names of `joints.parquet` (with `--joints`): one row per clip, frame and joint.
pub mod joints {
    /// `joint`: joint name (End Sites as `<parent>/End`).
    pub const JOINT: &str = "joint";
    /// World joint position, m.
    pub const POSITION: [&str; 3] = ["x_m", "y_m", "z_m"];
}

/// Column names of `kinematics.parquet` (one row per polytope facet) and of
/// `kinematics_points.parquet` / `kinematics_samples.parquet` (one row per point).
pub mod kinematics {
    /// `character_id`: the character.
    pub const CHARACTER_ID: &str = "character_id";
    /// `effector`: the contact effector whose frame the polytope is in.
    pub const EFFECTOR: &str = "effector";
    /// Facet normal in the contact frame (unit vector).
    pub const NORMAL: [&str; 3] = ["nx", "ny", "nz"];
    /// `d_m`: facet offset, `n·c ≤ d`, m.
    pub const OFFSET: &str = "d_m";
    /// `clip`: the point's clip.
    pub const CLIP: &str = "clip";
    /// `frame`: the point's frame.
    pub const FRAME: &str = "frame";
    /// COM relative to the contact in the contact frame, m.
    pub const POINT: [&str; 3] = ["x_m", "y_m", "z_m"];
    /// Columns of `kinematics.parquet`, in order.
    pub const FACET_COLUMNS: [&str; 6] = [
        CHARACTER_ID,
        EFFECTOR,
        NORMAL[0],
        NORMAL[1],
        NORMAL[2],
        OFFSET,
    ];
    /// Columns of `kinematics_points.parquet` and `kinematics_samples.parquet`, in order.
    pub const POINT_COLUMNS: [&str; 7] = [
        CHARACTER_ID,
        EFFECTOR,
        CLIP,
        FRAME,
        POINT[0],
        POINT[1],
        POINT[2],
    ];
}

/// Column names of `errors.parquet`: one row per failed input or stage.
pub mod errors {
    /// `path`: the input path as given.
    pub const PATH: &str = "path";
    /// `clip`: clip name, when the file got one.
    pub const CLIP: &str = "clip";
    /// `stage`: `parse`, `mapping`, `frames` or `stances`.
    pub const STAGE: &str = "stage";
    /// `message`: the error, naming the file, line or field.
    pub const MESSAGE: &str = "message";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 4] = [PATH, CLIP, STAGE, MESSAGE];
}

/// Columns of `clips.parquet`, in order.
pub const CLIPS_COLUMNS: [&str; 26] = clips::COLUMNS;
/// Fields of the `flights` struct in `clips.parquet`.
pub const FLIGHT_FIELDS: [&str; 11] = flights::COLUMNS;
/// Columns of `contacts.parquet`, in order.
pub const CONTACTS_COLUMNS: [&str; 18] = contacts::COLUMNS;
/// Columns of `stances.parquet`, in order (written by [`super::stances::stances_table`],
/// read by [`super::stances::read_stances`]).
pub const STANCES_COLUMNS: [&str; 85] = stances::COLUMNS;
/// Columns of `errors.parquet`, in order.
pub const ERRORS_COLUMNS: [&str; 4] = errors::COLUMNS;
/// Columns of `kinematics.parquet` (one row per facet), in order.
pub const KINEMATICS_COLUMNS: [&str; 6] = kinematics::FACET_COLUMNS;
/// Columns of `kinematics_points.parquet` and `kinematics_samples.parquet`, in order.
pub const KINEMATICS_POINTS_COLUMNS: [&str; 7] = kinematics::POINT_COLUMNS;

/// Column names of `clips.parquet`: one row per input file.
pub mod clips {
    /// `path`: The input path as given.
    pub const PATH: &str = "path";
    /// `clip`: Clip name (file stem, made unique).
    pub const CLIP: &str = "clip";
    /// `content_sha256`: SHA-256 of the file's bytes, hex.
    pub const CONTENT_SHA256: &str = "content_sha256";
    /// `status`: `ok`, `skipped` or `error`.
    pub const STATUS: &str = "status";
    /// `message`: Why a clip was skipped or failed.
    pub const MESSAGE: &str = "message";
    /// `frames_header`: `Frames:` of the file's header.
    pub const FRAMES_HEADER: &str = "frames_header";
    /// `frames_data`: MOTION rows actually present.
    pub const FRAMES_DATA: &str = "frames_data";
    /// `frames_kept`: Rows kept after the lead-in rule.
    pub const FRAMES_KEPT: &str = "frames_kept";
    /// `leadin_dropped`: Rows dropped as lead-in (list).
    pub const LEADIN_DROPPED: &str = "leadin_dropped";
    /// `frame_time_s`: `Frame Time:` of the file, s.
    pub const FRAME_TIME: &str = "frame_time_s";
    /// `unit_scale`: Metres per file unit (a conversion factor).
    pub const UNIT_SCALE: &str = "unit_scale";
    /// `unit`: The detected file unit.
    pub const UNIT: &str = "unit";
    /// `up_axis`: The detected up axis (`+Y`, …).
    pub const UP_AXIS: &str = "up_axis";
    /// `handedness_ok`: Left and right landmarks on the expected sides.
    pub const HANDEDNESS_OK: &str = "handedness_ok";
    /// `leg_length_m`: Leg length `L_leg`, m.
    pub const LEG_LENGTH: &str = "leg_length_m";
    /// `reach_m`: How far from its COM the body reaches a contact, m (straight leg below
    /// the hip, foot on its toe; the jump limits' `χ_max`). Null in libraries built before
    /// it existed.
    pub const REACH: &str = "reach_m";
    /// `character_id`: Character id (`sk-` + 12 hex digits of the skeleton).
    pub const CHARACTER_ID: &str = "character_id";
    /// `mass_kg`: Body mass, kg.
    pub const MASS: &str = "mass_kg";
    /// `mass_source`: Where the body mass came from: `table <file>:<line>` (`--masses`),
    /// `mass_kg` (`--mass`, a body or pipeline file) or `default` (70 kg assumed, a warning).
    pub const MASS_SOURCE: &str = "mass_source";
    /// `skeleton`: The landmark mapping (JSON).
    pub const SKELETON: &str = "skeleton";
    /// `toe_tip_rule_left`: How the left toe tip was found.
    pub const TOE_TIP_RULE_LEFT: &str = "toe_tip_rule_left";
    /// `toe_tip_rule_right`: How the right toe tip was found.
    pub const TOE_TIP_RULE_RIGHT: &str = "toe_tip_rule_right";
    /// `flights`: Flight fits (list of structs, [`super::flights`]).
    pub const FLIGHTS: &str = "flights";
    /// `flight_az_median_mps2`: Median vertical COM acceleration in flight, m/s².
    pub const FLIGHT_AZ_MEDIAN: &str = "flight_az_median_mps2";
    /// `s_eff`: Effective time scale of the clip's flights (dimensionless).
    pub const S_EFF: &str = "s_eff";
    /// `warnings`: Advisory messages (list).
    pub const WARNINGS: &str = "warnings";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 26] = [
        PATH,
        CLIP,
        CONTENT_SHA256,
        STATUS,
        MESSAGE,
        FRAMES_HEADER,
        FRAMES_DATA,
        FRAMES_KEPT,
        LEADIN_DROPPED,
        FRAME_TIME,
        UNIT_SCALE,
        UNIT,
        UP_AXIS,
        HANDEDNESS_OK,
        LEG_LENGTH,
        REACH,
        CHARACTER_ID,
        MASS,
        MASS_SOURCE,
        SKELETON,
        TOE_TIP_RULE_LEFT,
        TOE_TIP_RULE_RIGHT,
        FLIGHTS,
        FLIGHT_AZ_MEDIAN,
        S_EFF,
        WARNINGS,
    ];
}

/// Column names of fields of the `flights` struct of `clips.parquet`.
pub mod flights {
    /// `first_frame`: First airborne frame.
    pub const FIRST_FRAME: &str = "first_frame";
    /// `last_frame`: Last airborne frame.
    pub const LAST_FRAME: &str = "last_frame";
    /// `duration_s`: Flight duration, s.
    pub const DURATION: &str = "duration_s";
    /// `a_z_mps2`: Fitted vertical COM acceleration, m/s².
    pub const A_Z: &str = "a_z_mps2";
    /// `a_x_mps2`: Fitted horizontal (x) COM acceleration, m/s².
    pub const A_X: &str = "a_x_mps2";
    /// `a_y_mps2`: Fitted horizontal (y) COM acceleration, m/s².
    pub const A_Y: &str = "a_y_mps2";
    /// `rms_m`: Fit residual RMS, m.
    pub const RMS: &str = "rms_m";
    /// `s_eff`: Effective time scale of this flight (dimensionless).
    pub const S_EFF: &str = "s_eff";
    /// `a_z_mean_mps2`: Mean of the differentiated vertical COM acceleration, m/s².
    pub const A_Z_MEAN: &str = "a_z_mean_mps2";
    /// `ballistic`: The fit is within the ballistic tolerance of −g.
    pub const BALLISTIC: &str = "ballistic";
    /// `tested`: Long enough to be tested.
    pub const TESTED: &str = "tested";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 11] = [
        FIRST_FRAME,
        LAST_FRAME,
        DURATION,
        A_Z,
        A_X,
        A_Y,
        RMS,
        S_EFF,
        A_Z_MEAN,
        BALLISTIC,
        TESTED,
    ];
}

/// Column names of `contacts.parquet`: one row per contact run.
pub mod contacts {
    /// `clip`: Clip name.
    pub const CLIP: &str = "clip";
    /// `effector`: `left_foot`, `right_foot`, `left_hand` or `right_hand`.
    pub const EFFECTOR: &str = "effector";
    /// `first_frame`: First contact frame (file MOTION row).
    pub const FIRST_FRAME: &str = "first_frame";
    /// `last_frame`: Last contact frame.
    pub const LAST_FRAME: &str = "last_frame";
    /// `td_edge_clip_s`: Touchdown at the frame edge (half a frame before `first_frame`), clip time, s.
    pub const TD_EDGE: &str = "td_edge_clip_s";
    /// `lo_edge_clip_s`: Liftoff at the frame edge (half a frame after `last_frame`), clip time, s.
    pub const LO_EDGE: &str = "lo_edge_clip_s";
    /// `td_clip_s`: Touchdown, sub-frame estimate, clip time, s.
    pub const TD: &str = "td_clip_s";
    /// `lo_clip_s`: Liftoff, sub-frame estimate, clip time, s.
    pub const LO: &str = "lo_clip_s";
    /// `static`: The run was triggered by a static point.
    pub const STATIC: &str = "static";
    /// `speed_led`: The run was found by the speed rule alone.
    pub const SPEED_LED: &str = "speed_led";
    /// `surface_z_m`: Height of the contact surface, m.
    pub const SURFACE_Z: &str = "surface_z_m";
    /// `origin_x_m`: Contact-frame origin, world x, m.
    pub const ORIGIN_X: &str = "origin_x_m";
    /// `origin_y_m`: Contact-frame origin, world y, m.
    pub const ORIGIN_Y: &str = "origin_y_m";
    /// `origin_z_m`: Contact-frame origin, world z, m.
    pub const ORIGIN_Z: &str = "origin_z_m";
    /// `yaw_rad`: Contact-frame yaw about the up axis, rad.
    pub const YAW: &str = "yaw_rad";
    /// `normal_x`: Surface normal, world x (unit vector).
    pub const NORMAL_X: &str = "normal_x";
    /// `normal_y`: Surface normal, world y.
    pub const NORMAL_Y: &str = "normal_y";
    /// `normal_z`: Surface normal, world z.
    pub const NORMAL_Z: &str = "normal_z";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 18] = [
        CLIP,
        EFFECTOR,
        FIRST_FRAME,
        LAST_FRAME,
        TD_EDGE,
        LO_EDGE,
        TD,
        LO,
        STATIC,
        SPEED_LED,
        SURFACE_Z,
        ORIGIN_X,
        ORIGIN_Y,
        ORIGIN_Z,
        YAW,
        NORMAL_X,
        NORMAL_Y,
        NORMAL_Z,
    ];
}

/// Column names of `stances.parquet`: one row per stance.
pub mod stances {
    /// `stance_id`: `<clip>:<label>:<first frame>`.
    pub const STANCE_ID: &str = "stance_id";
    /// `clip`: Clip name.
    pub const CLIP: &str = "clip";
    /// `character_id`: Character id.
    pub const CHARACTER_ID: &str = "character_id";
    /// `label`: `L`, `R`, `LR`, `LR+LH`, …
    pub const LABEL: &str = "label";
    /// `effectors`: Effectors in contact (sorted list).
    pub const EFFECTORS: &str = "effectors";
    /// `first_frame`: First stance frame.
    pub const FIRST_FRAME: &str = "first_frame";
    /// `last_frame`: Last stance frame.
    pub const LAST_FRAME: &str = "last_frame";
    /// `td_clip_s`: Touchdown, clip time, s.
    pub const TD_CLIP: &str = "td_clip_s";
    /// `lo_clip_s`: Liftoff, clip time, s.
    pub const LO_CLIP: &str = "lo_clip_s";
    /// `td_stance_s`: Touchdown, stance time (from the start apex), s.
    pub const TD_STANCE: &str = "td_stance_s";
    /// `lo_stance_s`: Liftoff, stance time, s.
    pub const LO_STANCE: &str = "lo_stance_s";
    /// `end_apex_stance_s`: End apex `t_e`, stance time, s.
    pub const END_APEX_STANCE: &str = "end_apex_stance_s";
    /// `dt_s`: Ground time Δt, s.
    pub const DT: &str = "dt_s";
    /// `boundary_start`: What precedes the stance.
    pub const BOUNDARY_START: &str = "boundary_start";
    /// `boundary_end`: What follows the stance.
    pub const BOUNDARY_END: &str = "boundary_end";
    /// `rest_at_edge`: The stance starts or ends at a clip edge at rest (SG COM speed below
    /// 0.15 m/s there; cut where a quiet stretch reaching the edge begins or ends).
    pub const REST_AT_EDGE: &str = "rest_at_edge";
    /// `flight_before`: The preceding flight (struct, [`super::flight_ref`]).
    pub const FLIGHT_BEFORE: &str = "flight_before";
    /// `flight_after`: The following flight (struct).
    pub const FLIGHT_AFTER: &str = "flight_after";
    /// `heading_x`: Heading `e_h`, world x (unit vector).
    pub const HEADING_X: &str = "heading_x";
    /// `heading_y`: Heading `e_h`, world y.
    pub const HEADING_Y: &str = "heading_y";
    /// `heading_from`: Where the heading came from.
    pub const HEADING_FROM: &str = "heading_from";
    /// `z_c_m`: Contact height above the local floor, m.
    pub const Z_C: &str = "z_c_m";
    /// `zs_m`: Start apex height above `z_c`, m.
    pub const ZS: &str = "zs_m";
    /// `vs_mps`: Start apex horizontal velocity, m/s.
    pub const VS: &str = "vs_mps";
    /// `ze_m`: End apex height above `z_c`, m.
    pub const ZE: &str = "ze_m";
    /// `ve_mps`: End apex horizontal velocity, m/s.
    pub const VE: &str = "ve_mps";
    /// `vp_mps`: End apex lateral velocity, m/s.
    pub const VP: &str = "vp_mps";
    /// `x_m`: Apex-to-apex distance, m.
    pub const X: &str = "x_m";
    /// `vps_mps`: Start apex lateral velocity, m/s.
    pub const VPS: &str = "vps_mps";
    /// `z_td_m`: COM height above `z_c` at touchdown, m.
    pub const Z_TD: &str = "z_td_m";
    /// `z_lo_m`: COM height above `z_c` at liftoff, m.
    pub const Z_LO: &str = "z_lo_m";
    /// `ze_measured_m`: `ze` from the measured liftoff state, m.
    pub const ZE_MEASURED: &str = "ze_measured_m";
    /// `ve_measured_mps`: `ve` from the measured liftoff state, m/s.
    pub const VE_MEASURED: &str = "ve_measured_mps";
    /// `vp_measured_mps`: `vp` from the measured liftoff state, m/s.
    pub const VP_MEASURED: &str = "vp_measured_mps";
    /// `x_measured_m`: `x` from the measured liftoff state, m.
    pub const X_MEASURED: &str = "x_measured_m";
    /// `mass_kg`: Body mass, kg.
    pub const MASS: &str = "mass_kg";
    /// Fourier DC term per stance axis, N. (`_h`, `_p`, `_v`)
    pub const C0: [&str; 3] = ["c0_h_n", "c0_p_n", "c0_v_n"];
    /// Fourier harmonics per stance axis, cycles per stance (whole, or half for the
    /// half-range cosines). (`_h`, `_p`, `_v`)
    pub const HARMONIC: [&str; 3] = ["harmonic_h", "harmonic_p", "harmonic_v"];
    /// Fourier amplitudes per stance axis, N. (`_h`, `_p`, `_v`)
    pub const AMP: [&str; 3] = ["amp_h_n", "amp_p_n", "amp_v_n"];
    /// Fourier phases per stance axis, rad. (`_h`, `_p`, `_v`)
    pub const PHASE: [&str; 3] = ["phase_h_rad", "phase_p_rad", "phase_v_rad"];
    /// Force-fit residual per stance axis, N. (`_h`, `_p`, `_v`)
    pub const FIT_RMS: [&str; 3] = ["fit_rms_h_n", "fit_rms_p_n", "fit_rms_v_n"];
    /// Polynomial coefficients of `τ^k` per stance axis, N. (`_h`, `_p`, `_v`)
    pub const POLY: [&str; 3] = ["poly_h_n", "poly_p_n", "poly_v_n"];
    /// `ratio_h`: Ratio model `q_h` (coefficients of `τ^k`, dimensionless).
    pub const RATIO_H: &str = "ratio_h";
    /// `ratio_p`: Ratio model `q_p`.
    pub const RATIO_P: &str = "ratio_p";
    /// `force_model`: `ratio` or `fourier`.
    pub const FORCE_MODEL: &str = "force_model";
    /// Impulse `J = (Δt/m)∫f` per stance axis, m/s. (`_h`, `_p`, `_v`)
    pub const J: [&str; 3] = ["j_h_mps", "j_p_mps", "j_v_mps"];
    /// Moment `K = (Δt²/m)∫τf` per stance axis, m. (`_h`, `_p`, `_v`)
    pub const K: [&str; 3] = ["k_h_m", "k_p_m", "k_v_m"];
    /// `s̄ = K/J` per stance axis, s. (`_h`, `_p`, `_v`)
    pub const S_BAR: [&str; 3] = ["s_bar_h_s", "s_bar_p_s", "s_bar_v_s"];
    /// `support_ok`: `J_v > 0`.
    pub const SUPPORT_OK: &str = "support_ok";
    /// `unilateral_ok`: No pulling force.
    pub const UNILATERAL_OK: &str = "unilateral_ok";
    /// `min_f_v_n`: Smallest vertical force, N.
    pub const MIN_F_V: &str = "min_f_v_n";
    /// `a_f_n2`: `max f_a²` per stance axis (list of 3), N².
    pub const A_F: &str = "a_f_n2";
    /// `a_mu`: `max (f_t/f_v)²` on the active set (list of 2, dimensionless).
    pub const A_MU: &str = "a_mu";
    /// `f_peak_n`: Original peak force, N.
    pub const F_PEAK: &str = "f_peak_n";
    /// `mu_req`: Required friction on the 5 % active set.
    pub const MU_REQ: &str = "mu_req";
    /// `mu_req_robust`: Required friction on the 20 % active set.
    pub const MU_REQ_ROBUST: &str = "mu_req_robust";
    /// `ext_min_m`: Smallest COM–contact distance, m.
    pub const EXT_MIN: &str = "ext_min_m";
    /// `ext_max_m`: Largest COM–contact distance, m.
    pub const EXT_MAX: &str = "ext_max_m";
    /// `cp_h_m`: Contact point relative to the COM at touchdown, heading axis, m.
    pub const CP_H: &str = "cp_h_m";
    /// `cp_p_m`: Contact point relative to the COM at touchdown, lateral axis, m.
    pub const CP_P: &str = "cp_p_m";
    /// `ang_impulse_nms`: Angular impulse about the COM (list of 3), N·m·s.
    pub const ANG_IMPULSE: &str = "ang_impulse_nms";
    /// `ang_impulse_h0_nms`: Its contact-point-free part `H_0` (list of 3), N·m·s.
    pub const ANG_IMPULSE_H0: &str = "ang_impulse_h0_nms";
    /// `ell_r_min`: Appendix B box, χ_max ellipsoid, lower (list of 3, dimensionless).
    pub const ELL_R_MIN: &str = "ell_r_min";
    /// `ell_r_max`: Appendix B box, χ_max ellipsoid, upper.
    pub const ELL_R_MAX: &str = "ell_r_max";
    /// `ell_s_min`: Appendix B box, χ_min ellipsoid, lower.
    pub const ELL_S_MIN: &str = "ell_s_min";
    /// `ell_s_max`: Appendix B box, χ_min ellipsoid, upper.
    pub const ELL_S_MAX: &str = "ell_s_max";
    /// `warnings`: Advisory messages (list).
    pub const WARNINGS: &str = "warnings";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 85] = [
        STANCE_ID,
        CLIP,
        CHARACTER_ID,
        LABEL,
        EFFECTORS,
        FIRST_FRAME,
        LAST_FRAME,
        TD_CLIP,
        LO_CLIP,
        TD_STANCE,
        LO_STANCE,
        END_APEX_STANCE,
        DT,
        BOUNDARY_START,
        BOUNDARY_END,
        REST_AT_EDGE,
        FLIGHT_BEFORE,
        FLIGHT_AFTER,
        HEADING_X,
        HEADING_Y,
        HEADING_FROM,
        Z_C,
        ZS,
        VS,
        ZE,
        VE,
        VP,
        X,
        VPS,
        Z_TD,
        Z_LO,
        ZE_MEASURED,
        VE_MEASURED,
        VP_MEASURED,
        X_MEASURED,
        MASS,
        C0[0],
        C0[1],
        C0[2],
        HARMONIC[0],
        HARMONIC[1],
        HARMONIC[2],
        AMP[0],
        AMP[1],
        AMP[2],
        PHASE[0],
        PHASE[1],
        PHASE[2],
        FIT_RMS[0],
        FIT_RMS[1],
        FIT_RMS[2],
        POLY[0],
        POLY[1],
        POLY[2],
        RATIO_H,
        RATIO_P,
        FORCE_MODEL,
        J[0],
        J[1],
        J[2],
        K[0],
        K[1],
        K[2],
        S_BAR[0],
        S_BAR[1],
        S_BAR[2],
        SUPPORT_OK,
        UNILATERAL_OK,
        MIN_F_V,
        A_F,
        A_MU,
        F_PEAK,
        MU_REQ,
        MU_REQ_ROBUST,
        EXT_MIN,
        EXT_MAX,
        CP_H,
        CP_P,
        ANG_IMPULSE,
        ANG_IMPULSE_H0,
        ELL_R_MIN,
        ELL_R_MAX,
        ELL_S_MIN,
        ELL_S_MAX,
        WARNINGS,
    ];
}

/// Column names of fields of the `flight_before`/`flight_after` structs of `stances.parquet`.
pub mod flight_ref {
    /// `first_frame`: First airborne frame.
    pub const FIRST_FRAME: &str = "first_frame";
    /// `last_frame`: Last airborne frame.
    pub const LAST_FRAME: &str = "last_frame";
    /// `n_int`: Interior frames of the fit.
    pub const N_INT: &str = "n_int";
    /// `free`: The flight's fit was free (not pinned to −g).
    pub const FREE: &str = "free";
    /// `a_z_mps2`: Fitted vertical COM acceleration, m/s².
    pub const A_Z: &str = "a_z_mps2";
    /// `vel_mps`: World COM velocity at the stance edge (list of 3), m/s: of the −g
    /// parabola the stance's edge state comes from (the flight's own fit when there is
    /// none).
    pub const VEL: &str = "vel_mps";
    /// Every column, in file order.
    pub const COLUMNS: [&str; 6] = [FIRST_FRAME, LAST_FRAME, N_INT, FREE, A_Z, VEL];
}

/// Column names of an edit's `FILE.plan.parquet` (`stancelib edit`): one row per output
/// frame. The 3-vectors are `<prefix>_x_m`, `<prefix>_y_m`, `<prefix>_z_m` ([`edit_plan::axis_column`]).
pub mod edit_plan {
    /// The plan table beside `FILE.bvh`: `FILE` + this extension.
    pub const EXTENSION: &str = "plan.parquet";
    /// The plot beside `FILE.bvh`: `FILE` + this extension.
    pub const PLOT_EXTENSION: &str = "png";
    /// `time_clip_s`: Time of the frame in the written clip, s.
    pub const TIME: &str = "time_clip_s";
    /// `phase`: `stance`, `flight`, or `rest` (a jump's lead-in: the recording's own frames
    /// before its first touchdown).
    pub const PHASE: &str = "phase";
    /// `stance_id`: The source stance of a stance frame (null in flight).
    pub const STANCE_ID: &str = "stance_id";
    /// Prefix of the planned COM, m.
    pub const COM: &str = "com";
    /// Prefix of the COM of the written pose, m.
    pub const POSE_COM: &str = "pose_com";
    /// Prefix of the planned contact point, m (null in flight).
    pub const CONTACT: &str = "contact";
    /// Prefix of the support foot's contact point in the written pose, m (null in flight).
    pub const FOOT: &str = "foot";
    /// `stance_td_clip_s`: Touchdown of the frame's stance in the written clip, s.
    pub const STANCE_TD: &str = "stance_td_clip_s";
    /// `stance_lo_clip_s`: Liftoff of the frame's stance in the written clip, s.
    pub const STANCE_LO: &str = "stance_lo_clip_s";
    /// `converged`: COM and foot within tolerance.
    pub const CONVERGED: &str = "converged";
    /// `foot_error_m`: Largest distance of a support ankle from its goal in the written
    /// pose, m (0 in flight): what `converged` judges against 1 mm.
    pub const FOOT_ERROR: &str = "foot_error_m";
    /// `iterations`: Root-correction and IK iterations used.
    pub const ITERATIONS: &str = "iterations";
    /// `violated`: `<stance_id>: <constraint>` when the frame's stance breaks one.
    pub const VIOLATED: &str = "violated";
    /// `pelvis_turn_pitch_deg`, `_roll_deg`, `_yaw_deg`: The turn of the pelvis under the
    /// trunk that let a support leg reach (`edit::posture`; 0 where the reference pose
    /// reaches), deg.
    pub const PELVIS_TURN: [&str; 3] = [
        "pelvis_turn_pitch_deg",
        "pelvis_turn_roll_deg",
        "pelvis_turn_yaw_deg",
    ];
    /// `source_clip_s`: Clip time of the source pose the frame is taken from, s (in a
    /// flight between two stances, that of the edge weighing more in the blend).
    pub const SOURCE_TIME: &str = "source_clip_s";
    /// `trunk_lean_deg`: Trunk lean of the written pose (mid-hip to neck base against
    /// vertical, in the pelvis's sagittal plane; forward +), deg (`edit::fidelity`).
    pub const TRUNK_LEAN: &str = "trunk_lean_deg";
    /// `knee_flexion_left_deg`: Left knee flexion of the written pose, deg (0 = straight).
    pub const KNEE_LEFT: &str = "knee_flexion_left_deg";
    /// `knee_flexion_right_deg`: Right knee flexion of the written pose, deg.
    pub const KNEE_RIGHT: &str = "knee_flexion_right_deg";
    /// `root_accel_mps2`: Root acceleration from the written frames' second difference,
    /// m/s² (0 on the first and last frame).
    pub const ROOT_ACCEL: &str = "root_accel_mps2";

    /// The column of axis `a` (0 = x, 1 = y, 2 = z) of the 3-vector `prefix`, in m.
    pub fn axis_column(prefix: &str, a: usize) -> String {
        format!("{prefix}_{}_m", ["x", "y", "z"][a])
    }
}

/// COM-state columns shared by `twopac`'s `trajectory.parquet` / `quasi_static.parquet`
/// (written) and `equilibrium --points` (read): position, velocity, acceleration per axis.
pub mod com_state {
    /// `x_m, y_m, z_m`: COM position, m.
    pub const POSITION: [&str; 3] = ["x_m", "y_m", "z_m"];
    /// `vx_mps, vy_mps, vz_mps`: COM velocity, m/s.
    pub const VELOCITY: [&str; 3] = ["vx_mps", "vy_mps", "vz_mps"];
    /// `ax_mps2, ay_mps2, az_mps2`: COM acceleration, m/s² (optional on input: 0).
    pub const ACCELERATION: [&str; 3] = ["ax_mps2", "ay_mps2", "az_mps2"];
}
