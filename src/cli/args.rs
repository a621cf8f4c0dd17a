//! Raw command-line arguments (clap) and their validation into typed values.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::pipeline::spec::Overrides;
use crate::skeleton::units::{parse_unit, UpAxis};

/// stancelib: physically grounded stance libraries from motion-capture clips.
#[derive(Debug, Parser)]
#[command(name = "stancelib", version, about)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Per-frame COM, contacts and per-clip diagnostics of BVH clips, as Parquet.
    Frames(FramesArgs),
    /// Run a declarative pipeline file (pipelines/*.toml).
    Run(RunArgs),
    /// Build a stance library (stances, force models, constraint coefficients).
    Build(BuildArgs),
    /// Write a generated clip with known ground truth (fixtures).
    Synth(SynthArgs),
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
    /// File unit: m, cm, mm, in, cmu, or metres per file unit (default: detected).
    #[arg(long)]
    pub unit: Option<String>,
    /// Up axis of the files: +X, -X, +Y, -Y, +Z, -Z (default: detected).
    #[arg(long = "up-axis", allow_hyphen_values = true)]
    pub up_axis: Option<String>,
    /// Static / elevated contacts (multi-contact clips).
    #[arg(long = "static-contacts")]
    pub static_contacts: bool,
    /// Hands are not support effectors.
    #[arg(long = "no-hands")]
    pub no_hands: bool,
    /// Also write joints.parquet (every joint's world position).
    #[arg(long)]
    pub joints: bool,
    /// Refit each stance by least squares on the raw COM positions (Stage B).
    #[arg(long = "stage-b")]
    pub stage_b: bool,
    /// Worker threads (0 = all cores).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

impl BodyArgs {
    /// Validate into overrides.
    ///
    /// # Errors
    /// A mass, unit or up axis that does not parse.
    pub fn overrides(&self) -> anyhow::Result<Overrides> {
        let mass_kg = match self.mass {
            Some(m) if !(m.is_finite() && m > 0.0) => {
                anyhow::bail!("--mass must be a positive number of kg, found {m}")
            }
            m => m,
        };
        let unit_m = match &self.unit {
            Some(u) => Some(parse_unit(u).ok_or_else(|| {
                anyhow::anyhow!("--unit: '{u}' is not m, cm, mm, in, cmu or a positive number")
            })?),
            None => None,
        };
        let up_axis = match &self.up_axis {
            Some(a) => Some(UpAxis::parse(a).ok_or_else(|| {
                anyhow::anyhow!("--up-axis: '{a}' is not one of +X -X +Y -Y +Z -Z")
            })?),
            None => None,
        };
        Ok(Overrides {
            mass_kg,
            unit_m,
            up_axis,
            static_contacts: self.static_contacts,
            no_hands: self.no_hands,
            joints: self.joints,
        })
    }
}

/// `stancelib frames`.
#[derive(Debug, Args)]
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
#[derive(Debug, Args)]
pub struct BuildArgs {
    /// BVH files or folders (searched recursively for *.bvh).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Library folder (replaced atomically).
    #[arg(long)]
    pub out: PathBuf,
    /// Reuse the rows of clips whose path, content and options are unchanged.
    #[arg(long)]
    pub incremental: bool,
    /// Body and contact options.
    #[command(flatten)]
    pub body: BodyArgs,
}

/// `stancelib run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// Pipeline file.
    pub pipeline: PathBuf,
    /// Reuse the rows of clips whose path, content and options are unchanged.
    #[arg(long)]
    pub incremental: bool,
    /// Body and contact options (override the pipeline file).
    #[command(flatten)]
    pub body: BodyArgs,
}

/// `stancelib synth`.
#[derive(Debug, Args)]
pub struct SynthArgs {
    /// `run` or `jump`.
    #[arg(long, default_value = "run")]
    pub motion: String,
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
    #[arg(long, default_value = "Y")]
    pub up: String,
    /// Seed of the small pose perturbations.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output BVH file; the truth goes beside it as `<stem>.truth.csv`.
    #[arg(long)]
    pub out: PathBuf,
}
