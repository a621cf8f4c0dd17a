//! Raw command-line arguments (clap) and their validation into typed values.

use crate::force_model::ForceModelKind;
use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::library::storage::layout::Layout;
use crate::pipeline::commands::queries::{speed_range, LimitOptions};
use crate::pipeline::engine::shard::Shard;
use crate::pipeline::spec::Overrides;
use crate::query::feasibility::LimitForm;
use crate::query::map::Axis;
use crate::query::run::check_speed;
use crate::skeleton::units::{parse_unit, UpAxis};
use crate::synth::{SynthMotion, SynthUp};
use crate::twopac::transition::QpForm;

/// `--limits`: the limit form (§7.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum LimitFormArg {
    /// Per character.
    Absolute,
    /// Per stance.
    Relative,
}

impl From<LimitFormArg> for LimitForm {
    fn from(f: LimitFormArg) -> Self {
        match f {
            LimitFormArg::Absolute => LimitForm::Absolute,
            LimitFormArg::Relative => LimitForm::Relative,
        }
    }
}

/// `--layout`: how the library's tables are laid out on disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum LayoutArg {
    /// One Parquet file per table (`LIB/stances.parquet`).
    #[default]
    File,
    /// A hive-partitioned Parquet dataset per table
    /// (`LIB/stances/character_id=…/part-0.parquet`), for DuckDB, polars, pyarrow, Spark.
    Dataset,
}

impl From<LayoutArg> for Layout {
    fn from(l: LayoutArg) -> Self {
        match l {
            LayoutArg::File => Layout::File,
            LayoutArg::Dataset => Layout::Dataset,
        }
    }
}

/// `--up-axis`: the files' up axis (`X` = `+X`; any case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
#[value(rename_all = "verbatim")]
pub enum UpAxisArg {
    /// +X.
    #[value(name = "+X", alias = "X")]
    PosX,
    /// −X.
    #[value(name = "-X")]
    NegX,
    /// +Y.
    #[value(name = "+Y", alias = "Y")]
    PosY,
    /// −Y.
    #[value(name = "-Y")]
    NegY,
    /// +Z.
    #[value(name = "+Z", alias = "Z")]
    PosZ,
    /// −Z.
    #[value(name = "-Z")]
    NegZ,
}

impl From<UpAxisArg> for UpAxis {
    fn from(a: UpAxisArg) -> Self {
        match a {
            UpAxisArg::PosX => UpAxis::PosX,
            UpAxisArg::NegX => UpAxis::NegX,
            UpAxisArg::PosY => UpAxis::PosY,
            UpAxisArg::NegY => UpAxis::NegY,
            UpAxisArg::PosZ => UpAxis::PosZ,
            UpAxisArg::NegZ => UpAxis::NegZ,
        }
    }
}

/// `synth --motion`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MotionArg {
    /// Running: alternating single-foot stances and flights.
    Run,
    /// A countermovement jump in place.
    Jump,
}

impl From<MotionArg> for SynthMotion {
    fn from(m: MotionArg) -> Self {
        match m {
            MotionArg::Run => SynthMotion::Run,
            MotionArg::Jump => SynthMotion::Jump,
        }
    }
}

/// `synth --up`: the generated file's up axis (`+Y` = `Y`; any case).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
#[value(rename_all = "verbatim")]
pub enum SynthUpArg {
    /// Y up.
    #[value(alias = "+Y")]
    Y,
    /// Z up.
    #[value(alias = "+Z")]
    Z,
}

impl From<SynthUpArg> for SynthUp {
    fn from(u: SynthUpArg) -> Self {
        match u {
            SynthUpArg::Y => SynthUp::Y,
            SynthUpArg::Z => SynthUp::Z,
        }
    }
}

/// `twopac --form`: the transition QP form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
#[value(rename_all = "lower")]
pub enum QpFormArg {
    /// Equality form with wrench slack (eq 13).
    Eq13,
    /// Inequality form on the H-representation (eq 6).
    Eq6,
}

impl From<QpFormArg> for QpForm {
    fn from(f: QpFormArg) -> Self {
        match f {
            QpFormArg::Eq13 => QpForm::Eq13,
            QpFormArg::Eq6 => QpForm::Eq6,
        }
    }
}

/// stancelib: physically grounded stance libraries from motion-capture clips.
#[derive(Debug, Parser)]
#[command(name = "stancelib", version, about)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
    /// Print nothing on stdout and draw no progress bar (errors still go to stderr).
    #[arg(long, global = true)]
    pub quiet: bool,
    /// Print the command's summary as one JSON object on stdout instead of text
    /// (`frames`, `build`, `run`, `info`, `list`).
    #[arg(long, global = true)]
    pub json: bool,
}

/// The limits each subcommand checks before any work, for its `--help`.
fn limits_help(command: &str) -> Option<String> {
    use crate::query::map::{MAX_AXIS_VALUES, MAX_GRID_CELLS, MAX_MAP_CELLS};
    let range =
        format!("each start:stop:step range: at most {MAX_AXIS_VALUES} values (MAX_AXIS_VALUES)");
    let threads = format!(
        "--threads: at most {} × the cores (MAX_THREADS_PER_CORE)",
        crate::pipeline::engine::batch::MAX_THREADS_PER_CORE
    );
    let bvh = format!(
        "inputs: regular files of at most {} GiB (MAX_BVH_BYTES), lines of at most {} MiB \
         (MAX_LINE_BYTES)",
        crate::pipeline::engine::inputs::MAX_BVH_BYTES >> 30,
        crate::bvh::MAX_LINE_BYTES >> 20
    );
    let twopac = format!(
        "at most {} phases (MAX_PHASES), {} contacts per phase (MAX_CONTACTS), {} samples \
         of 0.01 s (validate::MAX_SAMPLES), {} rows per inline polytope (polytope::MAX_ROWS)",
        crate::twopac::trajectory::MAX_PHASES,
        crate::twopac::equilibrium::MAX_CONTACTS,
        crate::twopac::validate::MAX_SAMPLES,
        crate::twopac::polytope::MAX_ROWS
    );
    let lines: Vec<String> = match command {
        "frames" | "build" => vec![bvh, threads],
        "run" => vec![
            bvh,
            threads,
            format!(
                "inputs: at most {} globs (MAX_INPUT_PATTERNS)",
                crate::pipeline::spec::MAX_INPUT_PATTERNS
            ),
        ],
        "edit-run" | "edit-jump" => {
            let mut l = vec![
                format!(
                    "--fps {} to {} Hz (MIN_FPS, MAX_FPS)",
                    crate::edit::MIN_FPS,
                    crate::edit::MAX_FPS
                ),
                format!(
                    "output frames × skeleton joints: at most {} (MAX_EDIT_FRAME_JOINTS)",
                    crate::edit::MAX_EDIT_FRAME_JOINTS
                ),
            ];
            if command == "edit-run" {
                let cycles = format!("--cycles 1 to {} (MAX_CYCLES)", crate::edit::MAX_CYCLES);
                l.insert(0, cycles);
            }
            l
        }
        "run-query" => vec![
            range,
            format!(
                "cycles × speeds: at most {} rows (MAX_RUN_ROWS)",
                crate::query::run::MAX_RUN_ROWS
            ),
        ],
        "jumps" => vec![
            range,
            format!("heights × speeds: at most {MAX_GRID_CELLS} cells (MAX_GRID_CELLS)"),
            format!("cells × (pairs + stance grids): at most {MAX_MAP_CELLS} (MAX_MAP_CELLS)"),
        ],
        "twopac" => vec![twopac],
        "equilibrium" => vec![format!(
            "at most {} contacts (MAX_CONTACTS), {} COM states (MAX_COM_STATES), {} contacts × \
             (COM states + {} cells with --png) (MAX_CONTACT_STATES)",
            crate::twopac::equilibrium::MAX_CONTACTS,
            crate::twopac::equilibrium::MAX_COM_STATES,
            crate::twopac::equilibrium::MAX_CONTACT_STATES,
            crate::plot::equilibrium::DEFAULT_SLICE_CELLS.pow(2)
        )],
        "synth" => vec![format!(
            "--rate {} to {} Hz, --duration at most {} s",
            crate::synth::MIN_FRAME_RATE_HZ,
            crate::synth::MAX_FRAME_RATE_HZ,
            crate::synth::MAX_DURATION_S
        )],
        _ => return None,
    };
    let body: Vec<String> = lines.iter().map(|l| format!("  {l}")).collect();
    Some(format!(
        "Limits (checked before any work; exit 2 when exceeded):\n{}",
        body.join("\n")
    ))
}

/// The exit codes of the edits (`stancelib edit`, `edit run`, `edit jump`), for their
/// `--help`.
pub const EDIT_EXIT_HELP: &str = "Exit codes (the same for runs and jumps):
  0  feasible, every frame converged, posture and smoothness as recorded: written
  1  feasible and written, but some frames did not converge (COM or support foot off the
     plan) or the motion leaves the recording's posture or smoothness (trunk lean, knee
     flexion, a knee locked through a flight, a root acceleration spike); each on stderr
  2  fatal: bad options, unreadable library or source, no solution, or infeasible without
     --allow-infeasible (nothing written; the deciding constraint is named)
  3  infeasible, written with --allow-infeasible (the deciding constraint on stderr, the
     plan's `violated` column); frames that did not converge are also reported
Every edit prints the cycle or jump pair used, what it achieves (a run's speed, contact
times and step periods; a jump's apex and distance), and its verdict: the deciding
constraint with value, limit and margin in units (infeasible), or the constraint nearest
to breaking (feasible).";

/// The exit-code section of `command`'s `--help` (the edits), if any.
fn exit_help(command: &str) -> Option<String> {
    matches!(command, "edit" | "edit-run" | "edit-jump").then(|| EDIT_EXIT_HELP.to_string())
}

/// The clap command of [`Cli`], with every subcommand accepting negative numbers as
/// values (`--speed -3`, `--distance -0.5`) and listing its limits in `--help`.
pub fn command() -> clap::Command {
    fn adjust(c: clap::Command, parent: &str) -> clap::Command {
        let name = c.get_name().to_string();
        // `query run`, `edit run` and `run` share a name: key the first two by their parent.
        let key = match (parent, name.as_str()) {
            ("query", "run") => "run-query".to_string(),
            ("edit", _) => format!("edit-{name}"),
            _ => name.clone(),
        };
        let mut c = c.allow_negative_numbers(true);
        let help: Vec<String> = [limits_help(&key), exit_help(&key)]
            .into_iter()
            .flatten()
            .collect();
        if !help.is_empty() {
            c = c.after_help(help.join("\n\n"));
        }
        c.mut_subcommands(|s| adjust(s, &name))
    }
    adjust(<Cli as clap::CommandFactory>::command(), "")
}

/// Parses this process's arguments with [`command`] (exits with clap's message and
/// code 2 on bad arguments, as clap does).
pub fn parse() -> Cli {
    let matches = command().get_matches();
    <Cli as clap::FromArgMatches>::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// What a library holds: clips, characters, stances, failures, options, limits,
    /// provenance.
    Info(InfoArgs),
    /// A catalogue of a library: its characters, recorded run cycles and recorded jumps.
    ///
    /// Prints, in this order: the characters (id, clips, leg length, mass, stances), the
    /// run cycles (clip, stances, recorded speed, feasible at that speed under the default
    /// `query run`; cycles of clips whose time base is wrong are marked and left out, as
    /// `query run` does) and the recorded jumps (liftoff → landing, height, distance).
    ///
    /// With `--json`, one object: `library`; `characters[]` {`character_id`, `n_clips`,
    /// `clips`, `leg_length_m`, `mass_kg`, `n_stances`}; `run_cycles[]` {`clip`,
    /// `character_id`, `stance_ids`, `v_orig_mps`, `time_scaled`, `left_out`, `feasible_at_own_speed`
    /// (null when left out)}; `jumps[]` {`clip`, `character_id`, `liftoff`, `landing`,
    /// `height_m`, `distance_m`}.
    List(ListArgs),
    /// Per-frame COM, contacts and per-clip diagnostics of BVH clips, as Parquet.
    Frames(FramesArgs),
    /// Run a declarative pipeline file (pipelines/*.toml).
    Run(RunArgs),
    /// Build a stance library (stances, force models, constraint coefficients).
    Build(BuildArgs),
    /// Join shard libraries (`build --shard I/N`) into one library.
    Merge(MergeArgs),
    /// Write a generated clip with known ground truth (fixtures).
    Synth(SynthArgs),
    /// Scaled runs and jumps from a stance library.
    #[command(subcommand)]
    Query(QueryCommand),
    /// Feasibility maps over a stance library.
    #[command(subcommand)]
    Map(MapCommand),
    /// Equilibrium verdict and robustness margin of one contact set at many COM states.
    Equilibrium(EquilibriumArgs),
    /// 2PAC multi-contact COM trajectory of a contact phase sequence.
    Twopac(TwopacArgs),
    /// Every stance's model force on its evaluation grid (stance and world axes), as Parquet.
    Forces(ForcesArgs),
    /// Plots of a library's stances.
    #[command(subcommand)]
    Plot(PlotCommand),
    /// Edited motion as full-body BVH: scaled runs and jumps with planted feet.
    #[command(subcommand)]
    Edit(EditCommand),
}

/// `stancelib edit …`.
#[derive(Debug, Subcommand)]
pub enum EditCommand {
    /// Steady run cycles at a speed (the best feasible cycle, or `--stance`).
    Run(EditRunArgs),
    /// A liftoff → flight → landing at an apex height and distance.
    Jump(EditJumpArgs),
}

/// Options every edit shares.
#[derive(Debug, Args, Clone)]
pub struct EditCommon {
    /// Library folder (from `build` or `run`).
    #[arg(long)]
    pub lib: PathBuf,
    /// Output BVH file; `FILE.plan.parquet` and `FILE.png` are written beside it.
    #[arg(long)]
    pub out: PathBuf,
    /// Output frame rate, Hz (default: the source clip's).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Source BVH to take poses from, instead of the path recorded in `clips.parquet`.
    #[arg(long)]
    pub source: Option<PathBuf>,
    /// Write the motion even when the request breaks a constraint (exit 3; the deciding
    /// constraint on stderr, the sidecar says which per frame).
    #[arg(long = "allow-infeasible")]
    pub allow_infeasible: bool,
    /// Keep the cycles or jump pairs of clips the queries leave out (a copy of another
    /// clip's file, or a clip whose flights say its time base is wrong); they are named on
    /// stderr. A pair given with `edit jump --pair` is always kept.
    #[arg(long = "keep-left-out")]
    pub keep_left_out: bool,
    /// Limit form and μ (§7.5).
    #[command(flatten)]
    pub lim: LimitArgs,
}

/// `stancelib edit run`.
#[derive(Debug, Args, Clone)]
pub struct EditRunArgs {
    /// Library, output and shared options.
    #[command(flatten)]
    pub common: EditCommon,
    /// Target speed, m/s.
    #[arg(long)]
    pub speed: f64,
    /// Steady cycles written.
    #[arg(long, default_value_t = crate::edit::DEFAULT_CYCLES)]
    pub cycles: usize,
    /// The cycle's first stance (`<clip>:<label>:<first frame>`); default: the best
    /// feasible cycle.
    #[arg(long)]
    pub stance: Option<String>,
    /// Leg-length ratio target/recorded character (dynamic similarity, §9).
    #[arg(long = "length-scale", default_value_t = 1.0)]
    pub length_scale: f64,
    /// Body-mass ratio target/recorded character.
    #[arg(long = "mass-scale", default_value_t = 1.0)]
    pub mass_scale: f64,
    /// How contact time and step period change with speed, as `query run --gait-law`:
    /// `auto`, `population` or `paper` (the recorded cadence kept).
    #[arg(long = "gait-law", default_value = "auto", value_parser = ["auto", "population", "paper"])]
    pub gait_law: String,
}

/// `stancelib edit jump`.
#[derive(Debug, Args, Clone)]
pub struct EditJumpArgs {
    /// Library, output and shared options.
    #[command(flatten)]
    pub common: EditCommon,
    /// Flight apex height above the liftoff contact, m (default: the recorded pair's).
    #[arg(long, allow_hyphen_values = true)]
    pub height: Option<f64>,
    /// The recorded pair's apex height times this (instead of `--height`).
    #[arg(long = "height-scale", conflicts_with = "height")]
    pub height_scale: Option<f64>,
    /// Jump distance, m (default: the recorded pair's).
    #[arg(long, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// `LIFTOFF_ID:LANDING_ID`, both of one clip; default: the best feasible pair of one
    /// clip (with `--height` and `--distance`), or the library's first recorded jump
    /// (without them). A landing that does not follow its liftoff in the clip is turned
    /// onto the liftoff's heading. A clip name may hold ':': the pair is split at the ':'
    /// where both halves are stance ids of the library (no quoting).
    #[arg(long)]
    pub pair: Option<String>,
}

/// `stancelib plot …`.
#[derive(Debug, Subcommand)]
pub enum PlotCommand {
    /// One stance: model force against the kinematic (and plate) force, friction ratio.
    Stance(PlotStanceArgs),
    /// One clip: COM height with its flights' −g fits, COM speed, contact bars, warnings.
    Clip(PlotClipArgs),
}

/// `stancelib query …`.
#[derive(Debug, Subcommand)]
pub enum QueryCommand {
    /// Steady run cycles at a speed, by scaling recorded running stances (§6.8).
    Run(RunQueryArgs),
    /// Jumps of a height and distance from a liftoff and a landing stance (§6.9).
    Jump(JumpArgs),
}

/// `stancelib map …`.
#[derive(Debug, Subcommand)]
pub enum MapCommand {
    /// Jump feasibility over (u_apex, height) for every liftoff/landing pair (§6.10).
    Jumps(MapJumpsArgs),
}

/// Parses `start:stop:step` (inclusive) given as option `flag` into an axis.
///
/// # Errors
/// Not three finite numbers, a step ≤ 0, stop < start, or more values than
/// [`MAX_AXIS_VALUES`](crate::query::map::MAX_AXIS_VALUES).
pub fn parse_range(flag: &str, s: &str) -> anyhow::Result<Axis> {
    Ok(Axis::parse(flag, s)?)
}

/// The limit options shared by the queries (§7.5).
#[derive(Debug, Args, Clone, Default)]
pub struct LimitArgs {
    /// Limit form: absolute (per character) or relative (per stance) (§7.5).
    #[arg(long, value_enum)]
    pub limits: Option<LimitFormArg>,
    /// Friction limit μ, under either form: it replaces the absolute 0.7 and the
    /// relative 1.05 × the stance's own μ_req (force and extension limits keep the form).
    #[arg(long)]
    pub mu: Option<f64>,
    /// Active set of the friction check: where f_v ≥ FRACTION · max f_v (default 0.2, chosen
    /// from the force plates; the paper's is 0.05).
    #[arg(long = "active-set")]
    pub active_set: Option<f64>,
}

impl LimitArgs {
    /// The typed limit options (checked where they are used: [`LimitOptions::form`],
    /// [`LimitOptions::active_fraction`]).
    pub fn options(&self) -> LimitOptions {
        LimitOptions {
            form: self.limits.map(LimitForm::from),
            mu: self.mu,
            active_set: self.active_set,
        }
    }

    /// The limit form (`--limits`, else the query's `default`) and the given μ.
    ///
    /// # Errors
    /// A μ that is not a positive finite number.
    pub fn form(&self, default: LimitForm) -> anyhow::Result<(LimitForm, Option<f64>)> {
        self.options().form(default)
    }

    /// The friction check's active fraction `λ_act` (`--active-set`, else
    /// [`DEFAULT_QUERY_ACTIVE_FRACTION`](crate::query::feasibility::DEFAULT_QUERY_ACTIVE_FRACTION)).
    ///
    /// # Errors
    /// A fraction outside `[0, 1)` or not finite.
    pub fn active_fraction(&self) -> anyhow::Result<f64> {
        self.options().active_fraction()
    }
}

/// `stancelib query run`.
#[derive(Debug, Args, Clone)]
pub struct RunQueryArgs {
    /// Library folder (from `build` or `run`).
    #[arg(long)]
    pub lib: PathBuf,
    /// Target speed, m/s.
    #[arg(long, conflicts_with = "speeds")]
    pub speed: Option<f64>,
    /// A sweep of target speeds `start:stop:step` in m/s (e.g. 0:6:0.5 for Table 1).
    #[arg(long)]
    pub speeds: Option<String>,
    /// Leg-length ratio target/recorded character (dynamic similarity, §9).
    #[arg(long = "length-scale", default_value_t = 1.0)]
    pub length_scale: f64,
    /// Body-mass ratio target/recorded character.
    #[arg(long = "mass-scale", default_value_t = 1.0)]
    pub mass_scale: f64,
    /// Limit form and μ (§7.5).
    #[command(flatten)]
    pub lim: LimitArgs,
    /// Output Parquet file.
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw Table 1 as a figure (PNG) of four panels against the target speed: (a)
    /// each stance's contact time and step period, (b) the cycle's peak force against
    /// F_max, (c) the friction it needs, mu_min, against μ, (d) the leg extension extremes
    /// against χ_min and χ_max; one colour and marker per cycle, the limits dashed, each
    /// infeasible speed marked on the panel of the limit it violates, and under the title
    /// the speeds at which every cycle is feasible.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// How contact time and step period change with speed: `auto` (the character's own
    /// law when its cycles span speeds ≥ 1.2× apart, else `population`: contact time ∝
    /// v^-0.42, step period ∝ v^-0.19) or `paper` (every time kept, β_v = 1).
    #[arg(long = "gait-law", default_value = "auto", value_parser = ["auto", "population", "paper"])]
    pub gait_law: String,
    /// Keep the stances of clips the queries leave out (a copy of another clip's file, or
    /// a clip whose flights say its time base is wrong); they are named on stderr.
    #[arg(long = "keep-left-out")]
    pub keep_left_out: bool,
    /// Print one answer in full: the cycle whose first stance is this id (at each speed),
    /// with its gait-law times and, per stance, its scaling and every limit with value,
    /// limit and margin.
    #[arg(long, value_name = "STANCE_ID")]
    pub explain: Option<String>,
}

impl RunQueryArgs {
    /// The requested speeds.
    ///
    /// # Errors
    /// Neither option, a bad range, or a negative or non-finite speed.
    pub fn speeds(&self) -> anyhow::Result<Vec<f64>> {
        match (&self.speeds, self.speed) {
            (Some(r), _) => speed_range("--speeds", r),
            (None, Some(v)) => Ok(vec![check_speed("--speed", v)?]),
            (None, None) => anyhow::bail!("give --speed V or --speeds start:stop:step"),
        }
    }
}

/// `stancelib query jump`.
#[derive(Debug, Args, Clone)]
pub struct JumpArgs {
    /// Library folder.
    #[arg(long)]
    pub lib: PathBuf,
    /// Flight apex height above the liftoff contact, m (the same for every pair).
    #[arg(
        long,
        allow_hyphen_values = true,
        required_unless_present = "height_scale"
    )]
    pub height: Option<f64>,
    /// Each pair's own recorded apex height times this (e.g. 1.1: 10 % higher than
    /// recorded), instead of `--height`.
    #[arg(long = "height-scale", conflicts_with = "height")]
    pub height_scale: Option<f64>,
    /// Jump distance (liftoff start apex to landing end apex, along the heading), m;
    /// negative is backwards. Needed with `--height`.
    #[arg(long, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// Each pair's own recorded distance times this, instead of `--distance` (default 1
    /// with `--height-scale`: the recorded distance).
    #[arg(long = "distance-scale", conflicts_with = "distance")]
    pub distance_scale: Option<f64>,
    /// Print one answer in full: a rank of the printed table, or a stance id (the
    /// best-ranked pair with that liftoff or landing), with the flight and, per side, its
    /// scaling and every limit with value, limit and margin.
    #[arg(long, value_name = "RANK|STANCE_ID")]
    pub explain: Option<String>,
    /// Rows printed (the file has every pair).
    #[arg(long, default_value_t = 10)]
    pub top: usize,
    /// Keep the stances of clips the queries leave out (a copy of another clip's file, or
    /// a clip whose flights say its time base is wrong); they are named on stderr.
    #[arg(long = "keep-left-out")]
    pub keep_left_out: bool,
    /// Limit form and μ (§7.5).
    #[command(flatten)]
    pub lim: LimitArgs,
    /// Output Parquet file.
    #[arg(long)]
    pub out: PathBuf,
}

/// `stancelib map jumps`.
#[derive(Debug, Args, Clone)]
pub struct MapJumpsArgs {
    /// Library folder.
    #[arg(long)]
    pub lib: PathBuf,
    /// Rows: apex heights `start:stop:step`, m.
    #[arg(long, default_value = crate::query::map::DEFAULT_HEIGHTS_ARG)]
    pub heights: String,
    /// Columns: horizontal apex speeds `start:stop:step`, m/s.
    #[arg(long, default_value = crate::query::map::DEFAULT_SPEEDS_ARG)]
    pub speeds: String,
    /// Keep the stances of clips the queries leave out (a copy of another clip's file, or
    /// a clip whose flights say its time base is wrong); they are named on stderr.
    #[arg(long = "keep-left-out")]
    pub keep_left_out: bool,
    /// Limit form and μ (§7.5).
    #[command(flatten)]
    pub lim: LimitArgs,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw `jump_map_agreement.png`: where the fast filters (paper eq 10, 12) and the
    /// exact check agree (a developer diagnostic; the IoU is in `jump_map.json` anyway).
    #[arg(long)]
    pub diagnostics: bool,
}

impl MapJumpsArgs {
    /// The height axis.
    ///
    /// # Errors
    /// A bad range.
    pub fn heights(&self) -> anyhow::Result<Axis> {
        parse_range("--heights", &self.heights)
    }

    /// The speed axis.
    ///
    /// # Errors
    /// A bad range.
    pub fn speeds(&self) -> anyhow::Result<Axis> {
        parse_range("--speeds", &self.speeds)
    }
}

/// `ratio` or `fourier`.
fn parse_force_model(s: &str) -> Result<ForceModelKind, String> {
    ForceModelKind::parse(s).ok_or_else(|| format!("'{s}' is not a force model: ratio or fourier"))
}

/// Options shared by `frames` and `run` (each wins over the pipeline and body files).
#[derive(Debug, Args, Clone, Default)]
pub struct BodyArgs {
    /// Body file (TOML): mass, sex, unit, up axis, landmark names.
    #[arg(long)]
    pub body: Option<PathBuf>,
    /// Body mass in kg (default: body file, else 70).
    #[arg(long)]
    pub mass: Option<f64>,
    /// Per-clip body masses: a CSV table `clip,mass_kg[,sex]` (clip name or glob; the first
    /// matching row wins, over --mass). A clip without a mass gets 70 kg and a warning.
    #[arg(long)]
    pub masses: Option<PathBuf>,
    /// File unit: m, cm, mm, in, cmu, or metres per file unit (default: detected).
    #[arg(long)]
    pub unit: Option<String>,
    /// Up axis of the files: +X, -X, +Y, -Y, +Z, -Z (default: detected).
    #[arg(
        long = "up-axis",
        allow_hyphen_values = true,
        value_enum,
        ignore_case = true
    )]
    pub up_axis: Option<UpAxisArg>,
    /// Static / elevated contacts (multi-contact clips).
    #[arg(long = "static-contacts")]
    pub static_contacts: bool,
    /// Hands are not support effectors.
    #[arg(long = "no-hands")]
    pub no_hands: bool,
    /// Also write joints.parquet (every joint's world position).
    #[arg(long)]
    pub joints: bool,
    /// Worker threads (0 = all cores; at most 4 × the cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// Options of the stance stage (`build`, `run`; `frames` fits no force model).
#[derive(Debug, Args, Clone, Default)]
pub struct FitArgs {
    /// Stance force model: `ratio` (default; friction-faithful) or `fourier` (the paper's).
    #[arg(long = "force-model", value_parser = parse_force_model)]
    pub force_model: Option<ForceModelKind>,
}

impl BodyArgs {
    /// Validate into overrides.
    ///
    /// # Errors
    /// A mass, unit or up axis that does not parse; more threads than
    /// [`max_threads`](crate::pipeline::engine::batch::max_threads).
    pub fn overrides(&self) -> anyhow::Result<Overrides> {
        crate::pipeline::engine::batch::check_threads("--threads", self.threads)?;
        if let Some(m) = self.mass {
            crate::ingest::masses::check_body_mass(m)
                .map_err(|e| anyhow::anyhow!("--mass: {e}"))?;
        }
        let mass_kg = self.mass;
        let unit_m = match &self.unit {
            Some(u) => Some(parse_unit(u).ok_or_else(|| {
                anyhow::anyhow!("--unit: '{u}' is not m, cm, mm, in, cmu or a positive number")
            })?),
            None => None,
        };
        let up_axis = self.up_axis.map(UpAxis::from);
        Ok(Overrides {
            mass_kg,
            unit_m,
            up_axis,
            static_contacts: self.static_contacts,
            no_hands: self.no_hands,
            joints: self.joints,
            masses: self.masses.clone(),
        })
    }
}

/// `stancelib frames`.
#[derive(Debug, Args, Clone)]
pub struct FramesArgs {
    /// BVH files or folders (searched recursively for *.bvh).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Body and contact options.
    #[command(flatten)]
    pub body: BodyArgs,
}

/// `stancelib build`.
#[derive(Debug, Args, Clone)]
pub struct BuildArgs {
    /// BVH files or folders (searched recursively for *.bvh).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Library folder (replaced atomically; an existing folder only when it is a library
    /// or empty, never one that holds or lies in an input).
    #[arg(long)]
    pub out: PathBuf,
    /// Reuse the rows of clips whose path, content and options are unchanged.
    #[arg(long)]
    pub incremental: bool,
    /// Replace an existing `--out` folder that is not a stancelib library, and everything
    /// in it (never a file, nor a folder that holds or lies in an input).
    #[arg(long)]
    pub force: bool,
    /// Build only the I-th of N shards of the inputs (by content hash), for `merge`.
    #[arg(long, value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// Table layout: `file` (one Parquet file per table) or `dataset` (hive-partitioned
    /// by `character_id`); the rows are the same.
    #[arg(long, value_enum, default_value_t = LayoutArg::File)]
    pub layout: LayoutArg,
    /// Body and contact options.
    #[command(flatten)]
    pub body: BodyArgs,
    /// Stance-stage options.
    #[command(flatten)]
    pub fit: FitArgs,
}

/// `I/N`.
fn parse_shard(s: &str) -> Result<Shard, String> {
    s.parse::<Shard>().map_err(|e| e.to_string())
}

/// `stancelib merge`.
#[derive(Debug, Args, Clone)]
pub struct MergeArgs {
    /// Shard libraries, one per shard of one build (any order).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Library folder (the output rules of `build`; never one of the shards).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace an existing `--out` folder that is not a stancelib library (as `build`).
    #[arg(long)]
    pub force: bool,
    /// Table layout of the merged library (as `build --layout`; shards of either layout).
    #[arg(long, value_enum, default_value_t = LayoutArg::File)]
    pub layout: LayoutArg,
}

/// `stancelib run`.
#[derive(Debug, Args, Clone)]
pub struct RunArgs {
    /// Pipeline file.
    pub pipeline: PathBuf,
    /// Reuse the rows of clips whose path, content and options are unchanged.
    #[arg(long)]
    pub incremental: bool,
    /// Replace the pipeline's `out` folder when it is not a stancelib library (as
    /// `build --force`).
    #[arg(long)]
    pub force: bool,
    /// Body and contact options (override the pipeline file).
    #[command(flatten)]
    pub body: BodyArgs,
    /// Stance-stage options (override the pipeline file's `[fit]`).
    #[command(flatten)]
    pub fit: FitArgs,
}

/// `stancelib synth`.
#[derive(Debug, Args, Clone)]
pub struct SynthArgs {
    /// `run` or `jump`.
    #[arg(long, value_enum, ignore_case = true, default_value = "run")]
    pub motion: MotionArg,
    /// Frame rate, Hz.
    #[arg(long, default_value_t = 120.0)]
    pub rate: f64,
    /// Duration, s.
    #[arg(long, default_value_t = 1.5)]
    pub duration: f64,
    /// File unit: m, cm, in, cmu or metres per unit.
    #[arg(long, default_value = "m")]
    pub unit: String,
    /// Up axis of the file: Y or Z.
    #[arg(long, value_enum, ignore_case = true, default_value = "Y")]
    pub up: SynthUpArg,
    /// Seed of the small pose perturbations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output BVH file; the truth goes beside it as `<stem>.truth.csv`.
    #[arg(long)]
    pub out: PathBuf,
}

/// `stancelib equilibrium` (spec two-pac §8.2).
#[derive(Debug, Args, Clone)]
pub struct EquilibriumArgs {
    /// Contacts file (JSON, schema `stancelib.twopac.contacts/1`).
    #[arg(long)]
    pub contacts: PathBuf,
    /// COM states: Parquet with `x_m`, `y_m`, `z_m` and optionally `ax_mps2`, `ay_mps2`,
    /// `az_mps2` (the columns of `twopac`'s `trajectory.parquet`).
    #[arg(long)]
    pub points: PathBuf,
    /// Output Parquet file.
    #[arg(long)]
    pub out: PathBuf,
    /// Also draw a horizontal slice of the static-equilibrium region (margin per cell,
    /// zero acceleration) with the contacts and the evaluated COM states (PNG).
    #[arg(long)]
    pub png: Option<PathBuf>,
}

/// `stancelib twopac` (spec two-pac §1.1, §8).
#[derive(Debug, Args, Clone)]
pub struct TwopacArgs {
    /// Phase sequence (JSON, schema `stancelib.twopac.phases/1`).
    #[arg(long, required_unless_present = "clip")]
    pub phases: Option<PathBuf>,
    /// Phases from a recorded clip (two-pac §1.1 `--clip`; needs `--lib`).
    #[arg(long, conflicts_with = "phases")]
    pub clip: Option<PathBuf>,
    /// Library folder with `kinematics.parquet` (for named kinematic polytopes).
    #[arg(long)]
    pub lib: Option<PathBuf>,
    /// Character of the library's polytopes (default: the only one; needs `--lib`).
    #[arg(long, requires = "lib")]
    pub character: Option<String>,
    /// Transition QP form: `eq13` (equality form, default) or `eq6` (H-representation).
    #[arg(long, value_enum, default_value = "eq13")]
    pub form: QpFormArg,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
}

/// `stancelib forces`.
#[derive(Debug, Args, Clone)]
pub struct ForcesArgs {
    /// Library folder.
    #[arg(long)]
    pub lib: PathBuf,
    /// A stance id (`<clip>:<label>:<first frame>`); repeat for several (default: all).
    /// With `--per-contact`: one stance, whose frames are written.
    #[arg(long = "stance")]
    pub stances: Vec<String>,
    /// Per contact instead of the stance models: each foot's (and hand's) share of the
    /// clip's total force m(a + g) and its centre of pressure, frame by frame (needs one
    /// `--clip` or one `--stance`).
    #[arg(long = "per-contact")]
    pub per_contact: bool,
    /// With `--per-contact`: every frame of this clip (a name `stancelib list` prints).
    #[arg(long, conflicts_with = "stances")]
    pub clip: Option<String>,
    /// Output format: `parquet`, `csv` or `mot` (OpenSim ground reactions, Y up); `csv` and
    /// `mot` need `--per-contact` (default: from the `--out` extension, else parquet).
    #[arg(long, value_enum)]
    pub format: Option<ForcesFormat>,
    /// Output file.
    #[arg(long)]
    pub out: PathBuf,
}

/// `stancelib forces --format`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ForcesFormat {
    /// A Parquet table.
    Parquet,
    /// CSV text with a header.
    Csv,
    /// OpenSim `.mot` ground-reaction storage.
    Mot,
}

impl ForcesFormat {
    /// The format a file extension names (`parquet`, `csv`, `mot`).
    pub fn from_extension(path: &std::path::Path) -> Option<ForcesFormat> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "parquet" => Some(ForcesFormat::Parquet),
            "csv" => Some(ForcesFormat::Csv),
            "mot" => Some(ForcesFormat::Mot),
            _ => None,
        }
    }

    /// Its name, as `--format` takes it.
    pub fn as_str(self) -> &'static str {
        match self {
            ForcesFormat::Parquet => "parquet",
            ForcesFormat::Csv => "csv",
            ForcesFormat::Mot => "mot",
        }
    }
}

/// `stancelib plot stance`.
#[derive(Debug, Args, Clone)]
pub struct PlotStanceArgs {
    /// Library folder.
    #[arg(long)]
    pub lib: PathBuf,
    /// The stance id (`<clip>:<label>:<first frame>`).
    #[arg(long)]
    pub stance: String,
    /// Force-plate CSV of the stance's clip (`time_s`, `left_f{x,y,z}_n`, `right_…`,
    /// `f{x,y,z}_n`; N, the BVH file's axes).
    #[arg(long)]
    pub plates: Option<PathBuf>,
    /// Shade the active set `f_v ≥ FRACTION · max f_v` of the model, FRACTION in [0, 1]
    /// (default: the queries' friction check, whose `mu_req_robust` the plot shows).
    #[arg(long = "active-set", default_value_t = crate::query::feasibility::DEFAULT_QUERY_ACTIVE_FRACTION)]
    pub active_set: f64,
    /// Output PNG file.
    #[arg(long)]
    pub out: PathBuf,
}

/// `stancelib info`.
#[derive(Debug, Args, Clone)]
pub struct InfoArgs {
    /// Library folder (from `build` or `run`).
    pub lib: PathBuf,
}

/// `stancelib list` (its help is the doc of [`Command::List`]).
#[derive(Debug, Args, Clone)]
pub struct ListArgs {
    /// Library folder (from `build` or `run`).
    pub lib: PathBuf,
}

/// `stancelib plot clip`.
#[derive(Debug, Args, Clone)]
pub struct PlotClipArgs {
    /// Library folder.
    #[arg(long)]
    pub lib: PathBuf,
    /// The clip name (`clip` of `clips.parquet`).
    #[arg(long)]
    pub clip: String,
    /// Output PNG file.
    #[arg(long)]
    pub out: PathBuf,
}
