//! Shared test helpers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use stancelib::synth::{SynthMotion, SynthOptions, SynthUp};

/// `writeln!` into a per-test buffer, printed in one piece so that the output of tests
/// running in parallel does not interleave.
macro_rules! outln {
    ($buf:expr, $($t:tt)*) => {{
        use std::fmt::Write as _;
        writeln!($buf, $($t)*).unwrap();
    }};
}
pub(crate) use outln;

/// Environment variable that names the shared data folder in place of `../shared/data`
/// beside the checkout (tests only). Point it to a missing folder to run the suite as a
/// clone without the data runs (`STANCELIB_SHARED_DATA=/nonexistent cargo test`).
pub const SHARED_DATA_ENV: &str = "STANCELIB_SHARED_DATA";

/// The shared data folder: `$STANCELIB_SHARED_DATA` if set, else `../shared/data` beside
/// the checkout.
pub fn shared_data_dir() -> PathBuf {
    match std::env::var_os(SHARED_DATA_ENV) {
        Some(p) => PathBuf::from(p),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"),
    }
}

/// The shared data folder, if present.
pub fn shared_data() -> Option<PathBuf> {
    let p = shared_data_dir();
    p.is_dir().then_some(p)
}

/// Running in CI: `CI` set to anything but empty, `0` or `false` (CI services set
/// `CI=true`). There every test input must be present.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !matches!(v.as_str(), "" | "0" | "false"))
}

/// The one way a test skips: in CI ([`in_ci`]) it fails with `why`; elsewhere it writes
/// `SKIPPED <test>: <why>` and the caller returns.
///
/// The line goes straight to the process's stderr through the `std::io::stderr()` handle.
/// The test harness captures only what `print!`/`eprint!` write (and shows that for
/// failing tests only), so an `eprintln!` skip vanishes from a passing run; a write to the
/// handle is not captured and appears in the `cargo test` output, where the user sees it.
pub fn skip_or_fail(test: &str, why: &str) {
    // The harness names each test's thread after the test (`module::name`); `test` labels
    // the helper that asked (a library shared by several tests, say).
    let thread = std::thread::current();
    let test = match thread.name() {
        Some(name) if name != "main" && !name.ends_with(test) => format!("{name} ({test})"),
        Some(name) if name != "main" => name.to_string(),
        _ => test.to_string(),
    };
    assert!(!in_ci(), "{test}: {why}, and CI requires it");
    use std::io::Write;
    let line = format!("SKIPPED {test}: {why} (in CI this fails)\n");
    let _ = std::io::stderr().write_all(line.as_bytes());
}

/// The shared data folder for test `test`, the gate of every test that reads it: `None`
/// (after [`skip_or_fail`]: a failure in CI, a printed skip elsewhere) when it is absent.
pub fn shared_or_skip(test: &str) -> Option<PathBuf> {
    let d = shared_data();
    if d.is_none() {
        let why = format!(
            "the shared data folder {} is absent",
            shared_data_dir().display()
        );
        skip_or_fail(test, &why);
    }
    d
}

/// The layout of the shared data that the tests read: in CI the data must be there (one
/// failure that names the folder); elsewhere its absence is reported once by the gate.
#[test]
fn shared_data_present() {
    let Some(data) = shared_or_skip("shared_data_present") else {
        return;
    };
    for sub in ["bvh", "bvh-bulk/cmu", "forceplate"] {
        assert!(
            data.join(sub).is_dir(),
            "{}: no {sub}/ folder, which the shared-data tests read",
            data.display()
        );
    }
}

/// One committed fixture: the generator options and what ingest must detect.
pub struct FixtureCase {
    pub file: &'static str,
    pub motion: SynthMotion,
    pub rate: f64,
    pub duration: f64,
    pub unit_m: f64,
    pub unit: &'static str,
    pub up: SynthUp,
    pub up_axis: &'static str,
}

pub const FIXTURES: [FixtureCase; 5] = [
    FixtureCase {
        file: "run_120hz_m_yup",
        motion: SynthMotion::Run,
        rate: 120.0,
        duration: 1.5,
        unit_m: 1.0,
        unit: "m",
        up: SynthUp::Y,
        up_axis: "+Y",
    },
    FixtureCase {
        file: "run_60hz_cm_zup",
        motion: SynthMotion::Run,
        rate: 60.0,
        duration: 1.5,
        unit_m: 0.01,
        unit: "cm",
        up: SynthUp::Z,
        up_axis: "+Z",
    },
    FixtureCase {
        file: "run_30hz_in_yup",
        motion: SynthMotion::Run,
        rate: 30.0,
        duration: 2.0,
        unit_m: 0.0254,
        unit: "in",
        up: SynthUp::Y,
        up_axis: "+Y",
    },
    FixtureCase {
        file: "jump_120hz_cmu_yup",
        motion: SynthMotion::Jump,
        rate: 120.0,
        duration: 2.2,
        unit_m: 0.056444,
        unit: "cmu",
        up: SynthUp::Y,
        up_axis: "+Y",
    },
    FixtureCase {
        file: "jump_100hz_m_zup",
        motion: SynthMotion::Jump,
        rate: 100.0,
        duration: 2.2,
        unit_m: 1.0,
        unit: "m",
        up: SynthUp::Z,
        up_axis: "+Z",
    },
];

pub fn fixture_opts(c: &FixtureCase) -> SynthOptions {
    SynthOptions {
        motion: c.motion,
        frame_rate_hz: c.rate,
        duration_s: c.duration,
        unit_m: c.unit_m,
        up: c.up,
        seed: 1,
        platform_m: 0.0,
    }
}

pub fn fixture_path(c: &FixtureCase) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/bvh")
        .join(format!("{}.bvh", c.file))
}

/// Columns of a numeric CSV with a header; empty cells are NaN.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let mut cols = vec![Vec::new(); header.len()];
    for (i, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(
            cells.len(),
            header.len(),
            "{}: row {} has {} cells",
            path.display(),
            i + 2,
            cells.len()
        );
        for (c, cell) in cells.iter().enumerate() {
            let cell = cell.trim();
            cols[c].push(if cell.is_empty() {
                f64::NAN
            } else {
                cell.parse()
                    .unwrap_or_else(|_| panic!("{}: bad number {cell:?}", path.display()))
            });
        }
    }
    (header, cols)
}

pub fn csv_col<'a>(h: &[String], cols: &'a [Vec<f64>], name: &str) -> &'a [f64] {
    let i = h
        .iter()
        .position(|c| c == name)
        .unwrap_or_else(|| panic!("no column {name} in {h:?}"));
    &cols[i]
}

/// A force-plate clip of `../shared/data/forceplate`: metadata, mass, body weight, valid
/// window and the parsed kinematics.
pub struct ForcePlateClip {
    /// The clip folder.
    pub dir: PathBuf,
    /// `meta.json`.
    pub meta: serde_json::Value,
    /// Subject mass, kg.
    pub mass: f64,
    /// Body weight, N.
    pub bw: f64,
    /// `[t0, t1]` in which kinematics and plates are both valid, s.
    pub window: [f64; 2],
    /// `clip.bvh`, parsed.
    pub bvh: stancelib::bvh::Bvh,
}

/// Every `.bvh` under `dir` (recursively), sorted.
pub fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "bvh") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// The shared clips whose time base is wrong (`data/bvh/SOURCES.md`: the backflip plays
/// about 2× too fast, the fast run 15–25 % too fast): their flights are not ballistic at
/// the file's clock, whatever the contacts.
pub const TIME_SCALED_CLIPS: [&str; 2] = ["mass_backflip.bvh", "mass_run_fast.bvh"];

/// Load one force-plate clip (panics with the file name on a malformed input: test data).
pub fn forceplate_clip(data: &Path, clip: &str) -> ForcePlateClip {
    let dir = data.join("forceplate").join(clip);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).expect("meta.json"))
            .expect("meta.json is JSON");
    let num =
        |v: &serde_json::Value, what: &str| v.as_f64().unwrap_or_else(|| panic!("{clip}: {what}"));
    let (mass, bw) = (
        num(&meta["subject_mass_kg"], "subject_mass_kg"),
        num(&meta["body_weight_n"], "body_weight_n"),
    );
    let window = [
        num(&meta["window"][0], "window"),
        num(&meta["window"][1], "window"),
    ];
    let bvh = stancelib::bvh::parse_file(&dir.join("clip.bvh")).expect("clip.bvh parses");
    ForcePlateClip {
        dir,
        meta,
        mass,
        bw,
        window,
        bvh,
    }
}

/// What ingest makes of a body clip: summary, frames and contact runs.
pub type Ingested = (
    stancelib::ingest::ClipSummary,
    stancelib::ingest::ClipFrames,
    Vec<stancelib::ingest::ContactRun>,
);

/// Ingest a clip that must be a body (panics naming `what` on an error or a skip).
pub fn ingest_body(
    bvh: &stancelib::bvh::Bvh,
    opts: &stancelib::ingest::IngestOptions,
    what: &str,
) -> Ingested {
    use stancelib::ingest::{ingest, ClipOutcome};
    match ingest(bvh, opts).unwrap_or_else(|e| panic!("{what}: {e}")) {
        ClipOutcome::Body {
            summary,
            frames,
            contacts,
        } => (summary, frames, contacts),
        ClipOutcome::Skipped { reason, .. } => panic!("{what}: skipped: {reason}"),
    }
}

/// Ingest a committed fixture with default options: summary, frames and contact runs.
pub fn ingest_fixture(c: &FixtureCase) -> Ingested {
    let bvh = stancelib::bvh::parse_file(&fixture_path(c)).unwrap();
    ingest_body(&bvh, &Default::default(), c.file)
}

/// The checkout's root (the crate folder).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the binary: `(exit code, stdout, stderr)`.
pub fn stancelib(args: &[&str]) -> (i32, String, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_stancelib"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

/// Runs a command that must succeed; returns stdout.
pub fn ok(args: &[&str]) -> String {
    let (code, out, err) = stancelib(args);
    assert_eq!(code, 0, "stancelib {args:?}:\n{out}\n{err}");
    out
}

/// Runs a command that must fail with exit code 2 (fatal); returns stderr.
pub fn fails(args: &[&str]) -> String {
    let (code, out, err) = stancelib(args);
    assert_eq!(code, 2, "stancelib {args:?} must exit 2:\n{out}\n{err}");
    err
}

/// A path as an argument string.
pub fn s(p: &Path) -> String {
    p.display().to_string()
}

/// The generated clips `fixtures/bvh/*.bvh`, sorted.
pub fn fixture_clips() -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(root().join("fixtures/bvh"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "bvh"))
        .map(|p| s(&p))
        .collect();
    v.sort();
    v
}

/// The library of every generated clip with default options (`stancelib build
/// fixtures/bvh/*.bvh`, the demo's library without its query stages), built once per test
/// binary; read-only for the tests.
pub fn fixture_library() -> &'static Path {
    static LIB: std::sync::OnceLock<(tempfile::TempDir, PathBuf)> = std::sync::OnceLock::new();
    let (_, lib) = LIB.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let lib = dir.path().join("lib");
        let clips = fixture_clips();
        let mut args = vec!["build"];
        args.extend(clips.iter().map(String::as_str));
        let lib_s = s(&lib);
        args.extend(["--out", &lib_s]);
        ok(&args);
        (dir, lib)
    });
    lib
}

/// Manifest keys (at any depth) that change from one build to the next: build date,
/// command line, wall time, and the digest of the source the tool was compiled from (it
/// changes with every commit, the rows only with the ones that change them).
pub const MANIFEST_VOLATILE_KEYS: [&str; 4] = [
    "created_utc",
    "command_line",
    "wall_time_s",
    "source_digest",
];

/// `v` without [`MANIFEST_VOLATILE_KEYS`], at every depth.
pub fn without_volatile(v: serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Object(m) => Value::Object(
            m.into_iter()
                .filter(|(k, _)| !MANIFEST_VOLATILE_KEYS.contains(&k.as_str()))
                .map(|(k, v)| (k, without_volatile(v)))
                .collect(),
        ),
        Value::Array(a) => Value::Array(a.into_iter().map(without_volatile).collect()),
        other => other,
    }
}

/// `manifest.json` of a library (or any such file) without what changes from run to run.
pub fn stable_manifest(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let v = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    without_volatile(v)
}

/// Every file below `dir`, relative to it, sorted (empty when `dir` does not exist).
pub fn files_below(dir: &Path) -> std::collections::BTreeSet<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut std::collections::BTreeSet<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.insert(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut out = std::collections::BTreeSet::new();
    if dir.is_dir() {
        walk(dir, dir, &mut out);
    }
    out
}

/// Every file below `dir` with its bytes (relative paths).
pub fn snapshot(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    files_below(dir)
        .into_iter()
        .map(|rel| {
            let bytes = std::fs::read(dir.join(&rel)).unwrap();
            (rel, bytes)
        })
        .collect()
}

/// A scratch folder laid out like a checkout after `make demo`: `fixtures` (a link to the
/// repository's), `pipelines/demo.toml` (a copy) and `out/demo`, built by
/// `stancelib run pipelines/demo.toml` from inside it, as `make demo` does.
pub struct Demo {
    /// The scratch folder (removed on drop).
    pub dir: tempfile::TempDir,
}

impl Demo {
    /// The folder with `out/demo` built by the demo pipeline (library and query stages).
    pub fn build() -> Demo {
        let demo = Demo::empty();
        let (code, out, err) = demo.sh("stancelib run pipelines/demo.toml");
        assert_eq!(code, 0, "make demo's command failed:\n{out}\n{err}");
        demo
    }

    /// The folder with `out/demo` a plain library of the fixtures (no query stages).
    pub fn library() -> Demo {
        let demo = Demo::empty();
        let (code, out, err) = demo.sh("stancelib build fixtures/bvh/*.bvh --out out/demo");
        assert_eq!(code, 0, "{out}\n{err}");
        demo
    }

    /// The folder without any output yet.
    pub fn empty() -> Demo {
        let dir = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink(root().join("fixtures"), dir.path().join("fixtures")).unwrap();
        std::fs::create_dir(dir.path().join("pipelines")).unwrap();
        std::fs::copy(
            root().join("pipelines/demo.toml"),
            dir.path().join("pipelines/demo.toml"),
        )
        .unwrap();
        Demo { dir }
    }

    /// `out/demo` inside the folder.
    pub fn lib(&self) -> PathBuf {
        self.dir.path().join("out/demo")
    }

    /// Runs `line` with `sh -c` in the demo folder, the binary under test first on PATH.
    pub fn sh(&self, line: &str) -> (i32, String, String) {
        let bin = Path::new(env!("CARGO_BIN_EXE_stancelib"));
        let path = format!(
            "{}:{}",
            bin.parent().unwrap().display(),
            std::env::var("PATH").unwrap_or_default()
        );
        let o = std::process::Command::new("sh")
            .args(["-c", line])
            .current_dir(self.dir.path())
            .env("PATH", path)
            .output()
            .unwrap();
        (
            o.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&o.stdout).into(),
            String::from_utf8_lossy(&o.stderr).into(),
        )
    }
}

/// Runs a command that must exit 2 with every one of `needles` in its stderr; returns it.
pub fn refused(args: &[&str], needles: &[&str]) -> String {
    let err = fails(args);
    for n in needles {
        assert!(
            err.contains(n),
            "stancelib {args:?}: stderr lacks {n:?}:\n{err}"
        );
    }
    err
}

/// The names in a folder (empty when it does not exist).
pub fn listing(dir: &Path) -> Vec<String> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<String> = rd
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The key-value metadata of a Parquet file's footer (`ARROW:schema` included).
pub fn parquet_kv(path: &Path) -> std::collections::BTreeMap<String, String> {
    let mut f = std::fs::File::open(path).unwrap();
    let meta = polars_parquet::read::read_metadata(&mut f).unwrap();
    meta.key_value_metadata()
        .iter()
        .flatten()
        .map(|kv| (kv.key.clone(), kv.value.clone().unwrap_or_default()))
        .collect()
}

/// The string column `name` of `t` at `row` (`None` where null).
pub fn string_at(
    t: &stancelib::library::codec::table::Table,
    name: &str,
    row: usize,
) -> Option<String> {
    t.df.column(name)
        .unwrap_or_else(|_| panic!("no column {name}"))
        .str()
        .unwrap_or_else(|_| panic!("{name} is not a string column"))
        .get(row)
        .map(str::to_string)
}

/// The first stance id of each row of a `query run` table: the row's cycle.
pub fn first_stance_ids(t: &stancelib::library::codec::table::Table) -> Vec<String> {
    let lists = t.df.column("stance_ids").unwrap().list().unwrap().clone();
    (0..t.height())
        .map(|i| {
            let s = lists.get_as_series(i).unwrap();
            s.str().unwrap().get(0).unwrap().to_string()
        })
        .collect()
}

/// Record the present bytes of every table of the library `lib` in its manifest (the
/// content hashes of `library::storage::integrity`), as if the library had been written so: for
/// tests of the checks behind the hashes, on tables changed on purpose.
pub fn reseal(lib: &Path) {
    let p = lib.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    let digests = stancelib::library::storage::integrity::library_digests(lib).unwrap();
    m[stancelib::library::storage::integrity::TABLES_KEY] = serde_json::to_value(digests).unwrap();
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}
