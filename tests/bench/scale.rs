//! Peak memory and wall time of `build` against the size of the collection (issue 16).
//!
//! Run with `cargo bench --profile profiling --bench scale` (`make bench`). Input: every
//! `*.bvh` under `$SCALE_DIR`, else `../shared/data/bvh-bulk/cmu` (93 CMU clips); without
//! either it prints why and exits. The replica is `$SCALE_REPLICAS` (default
//! [`DEFAULT_REPLICAS`]) copies of those files under new names in a temporary folder, laid
//! out as `tests/bench/replica.sh` lays them out (`rNN/rNN_<name>.bvh`; copies, not links:
//! the build reads a file reached twice through links once).
//!
//! Each of `$SCALE_ROUNDS` rounds (default [`DEFAULT_ROUNDS`]) runs the `stancelib` binary
//! as a child, `build DIR --out LIB --threads 2`, on the set and on the replica, one after
//! the other, and reads each child's peak RSS from the kernel (`wait4`'s `ru_maxrss`). It
//! prints the medians, the replica's peak over the set's (target ≤ 1.3×, and ≤ 1 GiB) and
//! its wall time over K × the set's (target within 10 % of linear). Then it builds the
//! replica as [`SHARDS`] shards (`build --shard I/N`, not timed) and times `merge` of
//! them in each round: its wall time over the replica's build (target ≤ 10 %) and its
//! peak. Nothing is asserted: the figures are printed for the record.
//!
//! # Results
//! 2026-12-06 (third session), `SCALE_ROUNDS=3`, after batches are handed over without a
//! barrier (`pipeline::engine::ordered`):
//!
//! ```text
//! scale: 93 clips and a 25× replica, build --threads 2, 3 rounds (medians)
//! set      wall   0.687 s  peak    66.1 MiB
//! replica  wall  14.833 s  peak    80.9 MiB
//! replica / set: peak 1.22× (target ≤ 1.3×, ≤ 1024 MiB), wall 0.86× of linear (target ≤ 1.10)
//! merge of 8 shards  wall   2.484 s  peak   112.4 MiB: 17 % of the replica's build (target ≤ 10 %)
//! ```
//! The merge is as before; the build is faster, so its share grew.
//!
//! 2026-12-06 (second session, a slower hour for the same sandbox), `SCALE_ROUNDS=3`, after
//! the merge's copy moved to a thread of its own beside the polytopes and the streamed
//! hull's early drop and anchors:
//!
//! ```text
//! scale: 93 clips and a 25× replica, build --threads 2, 3 rounds (medians)
//! set      wall   0.779 s  peak    63.1 MiB
//! replica  wall  15.555 s  peak    78.9 MiB
//! replica / set: peak 1.25× (target ≤ 1.3×, ≤ 1024 MiB), wall 0.80× of linear (target ≤ 1.10)
//! merge of 8 shards  wall   2.500 s  peak   111.6 MiB: 16 % of the replica's build (target ≤ 10 %)
//! ```
//! `farm-bench` A/B against 70ad962 in the same hour (3 pairs): merge 2.52 against 4.66 s
//! (0.53×). Before the anchors: 2.754 s, 16 % of a 16.872 s build.
//!
//! 2026-12-06 (later), same sandbox, `SCALE_ROUNDS=3`, after the per-clip row groups, the
//! merge's copy of them and the parallel polytopes:
//!
//! ```text
//! scale: 93 clips and a 25× replica, build --threads 2, 3 rounds (medians)
//! set      wall   0.624 s  peak    70.7 MiB
//! replica  wall  14.268 s  peak    89.9 MiB
//! replica / set: peak 1.27× (target ≤ 1.3×, ≤ 1024 MiB), wall 0.92× of linear (target ≤ 1.10)
//! merge of 8 shards  wall   4.316 s  peak   132.2 MiB: 30 % of the replica's build (target ≤ 10 %)
//! ```
//! Memory and linearity met; the merge is not (`docs/decisions.md`, issue 16 item 2: it
//! must refit the polytopes over every kinematic sample). `farm-bench` A/B against the
//! commit before the session (3 pairs): merge 3.82 against 6.58 s, build 14.09 against
//! 14.29 s.
//!
//! 2026-12-06, 2-core sandbox, nothing else running, `SCALE_ROUNDS=3`, after the per-clip
//! limit summaries (`stances::limits::group_facts`), the count-bounded waiting rows
//! (`PENDING_SPILL_CHUNKS`) and the compact per-clip outcomes (`library::ClipStatus`):
//!
//! ```text
//! scale: 93 clips and a 25× replica, build --threads 2, 3 rounds (medians)
//! set      wall   0.553 s  peak    80.9 MiB
//! replica  wall  13.299 s  peak   101.1 MiB
//! replica / set: peak 1.25× (target ≤ 1.3×, ≤ 1024 MiB), wall 0.96× of linear (target ≤ 1.10)
//! ```
//! Targets met. `farm-bench` on the same commands, each against the binary before the
//! three changes (A/B, medians): set 7 runs 84.2 / 81.4 MiB, replica 3 runs 100.8 /
//! 117.8 MiB (1.20× and 1.45× of their sets).
//!
//! 2026-12-03, 2-core sandbox, nothing else running, `SCALE_ROUNDS=1`:
//!
//! ```text
//! scale: 93 clips and a 25× replica, build --threads 2, 1 rounds (medians)
//! set      wall   0.850 s  peak    80.8 MiB
//! replica  wall  18.477 s  peak   114.4 MiB
//! replica / set: peak 1.42× (target ≤ 1.3×, ≤ 1024 MiB), wall 0.87× of linear (target ≤ 1.10)
//! ```
//! Target missed: the peak ratio (`farm-bench -n 3` on the same commands: 82.0 and
//! 117.6 MiB, 1.43×).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use stancelib::pipeline::engine::inputs::discover;

/// The bulk set, relative to the crate root.
const BULK: &str = "../shared/data/bvh-bulk/cmu";
/// Copies in the replica when `$SCALE_REPLICAS` is not set (issue 16: a 25× replica).
const DEFAULT_REPLICAS: usize = 25;
/// Rounds when `$SCALE_ROUNDS` is not set.
const DEFAULT_ROUNDS: usize = 3;
/// Target of the replica's peak over the set's (issue 16).
const TARGET_RATIO: f64 = 1.3;
/// Shards of the replica merged (issue 16: 8 shard libraries).
const SHARDS: usize = 8;
/// Target of the merge's wall time over the replica's build (issue 16).
const TARGET_MERGE: f64 = 0.10;

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or(default)
}

/// `k` renamed copies of `files` under `dst` (`rNN/rNN_<name>`).
fn replica(files: &[PathBuf], dst: &Path, k: usize) -> std::io::Result<()> {
    for n in 1..=k {
        let d = dst.join(format!("r{n:02}"));
        std::fs::create_dir_all(&d)?;
        for f in files {
            let name = f.file_name().unwrap_or_default().to_string_lossy();
            std::fs::copy(f, d.join(format!("r{n:02}_{name}")))?;
        }
    }
    Ok(())
}

/// Wall time (s) and peak RSS (MiB) of `bin build input --out out --threads 2`.
fn build(bin: &str, input: &Path, out: &Path) -> (f64, f64) {
    let _ = std::fs::remove_dir_all(out);
    let mut args = vec!["build".into(), input.as_os_str().to_owned()];
    args.extend(["--out".into(), out.as_os_str().to_owned()]);
    args.extend(["--threads".into(), "2".into()]);
    run(bin, &args)
}

/// Wall time (s) and peak RSS (MiB) of `bin --quiet ARGS`, which must succeed.
#[expect(
    clippy::zombie_processes,
    reason = "the child is reaped by wait4, which also gives its own peak RSS"
)]
fn run(bin: &str, args: &[std::ffi::OsString]) -> (f64, f64) {
    let t0 = Instant::now();
    let child = Command::new(bin)
        .arg("--quiet")
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start stancelib");
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: `rusage` is plain data, zero is a valid value, and wait4 only writes it and
    // `status`; the child is ours and not waited for elsewhere.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let got = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    let wall = t0.elapsed().as_secs_f64();
    assert!(
        got == pid && libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "stancelib {args:?} failed (status {status})"
    );
    (wall, usage.ru_maxrss as f64 / 1024.0)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    if std::env::args().any(|a| a == "--list") {
        return;
    }
    let dir = std::env::var("SCALE_DIR").map_or_else(|_| PathBuf::from(BULK), PathBuf::from);
    // The inputs `build` itself would take (`pipeline::engine::inputs::discover`).
    let files = discover(std::slice::from_ref(&dir)).unwrap_or_default();
    if files.is_empty() {
        println!(
            "scale: no *.bvh under {} (set SCALE_DIR): skipped",
            dir.display()
        );
        return;
    }
    let (k, rounds) = (
        env_usize("SCALE_REPLICAS", DEFAULT_REPLICAS),
        env_usize("SCALE_ROUNDS", DEFAULT_ROUNDS),
    );
    let bin = env!("CARGO_BIN_EXE_stancelib");
    let tmp = tempfile::tempdir().expect("temporary folder");
    let rep = tmp.path().join("replica");
    replica(&files, &rep, k).expect("write the replica");
    // Copies are named by file name: two inputs of one name in different folders would
    // overwrite each other and make the replica smaller than k × the set.
    let copies = discover(std::slice::from_ref(&rep))
        .unwrap_or_default()
        .len();
    if copies != k * files.len() {
        println!(
            "scale: the replica has {copies} clips, not {k} × {} (inputs with the same file \
             name in different folders): skipped",
            files.len()
        );
        return;
    }
    let (mut set, mut big) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        set.push(build(bin, &dir, &tmp.path().join("lib_set")));
        big.push(build(bin, &rep, &tmp.path().join("lib_replica")));
    }
    let wall = |v: &[(f64, f64)]| median(v.iter().map(|r| r.0).collect());
    let peak = |v: &[(f64, f64)]| median(v.iter().map(|r| r.1).collect());
    let (ws, wr, ps, pr) = (wall(&set), wall(&big), peak(&set), peak(&big));
    println!(
        "scale: {} clips and a {k}× replica, build --threads 2, {rounds} rounds (medians)",
        files.len()
    );
    println!("set      wall {ws:7.3} s  peak {ps:7.1} MiB");
    println!("replica  wall {wr:7.3} s  peak {pr:7.1} MiB");
    println!(
        "replica / set: peak {:.2}× (target ≤ {TARGET_RATIO}×, ≤ 1024 MiB), wall {:.2}× of linear (target ≤ 1.10)",
        pr / ps,
        wr / (k as f64 * ws)
    );
    let shards: Vec<PathBuf> = (1..=SHARDS)
        .map(|i| tmp.path().join(format!("shard_{i}")))
        .collect();
    for (i, out) in shards.iter().enumerate() {
        let mut args = vec!["build".into(), rep.as_os_str().to_owned()];
        args.extend(["--shard".into(), format!("{}/{SHARDS}", i + 1).into()]);
        args.extend(["--out".into(), out.as_os_str().to_owned()]);
        args.extend(["--threads".into(), "2".into()]);
        run(bin, &args);
    }
    let merged = tmp.path().join("lib_merged");
    let merges: Vec<(f64, f64)> = (0..rounds)
        .map(|_| {
            let _ = std::fs::remove_dir_all(&merged);
            let mut args = vec!["merge".into()];
            args.extend(shards.iter().map(|s| s.as_os_str().to_owned()));
            args.extend(["--out".into(), merged.as_os_str().to_owned()]);
            run(bin, &args)
        })
        .collect();
    let (wm, pm) = (wall(&merges), peak(&merges));
    println!(
        "merge of {SHARDS} shards  wall {wm:7.3} s  peak {pm:7.1} MiB: {:.0} % of the replica's build (target ≤ {:.0} %)",
        100.0 * wm / wr,
        100.0 * TARGET_MERGE
    );
}
