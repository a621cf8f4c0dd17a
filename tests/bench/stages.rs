//! Stage benchmarks: BVH parsing, FK + COM per frame, and a whole-clip ingest.
//!
//! Run with `cargo bench --bench stages` (`make bench`). Input: the CMU clip
//! `../shared/data/bvh/jump/cmu_01_01_forward_jumps_mb.bvh` (2752 frames, 31 joints,
//! 96 channels, 2.07 MB). Without `../shared` a seeded synthetic clip with the same
//! 31-joint CMU skeleton and frame count is benchmarked instead (`make_clip`);
//! `STAGES_CLIP=<path>` benchmarks another CMU-unit clip with a toe End Site, and
//! `STAGES_CLIP=synthetic` forces the synthetic one.
//!
//! Groups:
//! - `parse`: `bvh::parse_reader` on the in-memory bytes vs `baseline_split_parse`, a plain
//!   `split_ascii_whitespace` + `fast_float2::parse` loop over the MOTION lines
//!   (throughput in bytes of the whole file). Target: within 2× of the baseline
//!   (CORRECTIONS issue 2 item 9).
//! - `fk_com`: parsed channels in memory → every joint and End Site (`fk::forward`),
//!   each point to Z-up metres `(x, −z, y)·0.056444`, the toe tips, contact points (toe
//!   tip and ankle) and the de Leva COM (`com::com`), per frame (throughput in frames).
//!   Target: floor 0.5 M frames/s per core, goal 1.5 M. Diagnosis: `fk_only`,
//!   `units_com_only` (given the points), `trig_only` (libm `sin_cos`, one per rotation
//!   channel) and `trig_only_poly` (`math::trig::sincos_deg`, scalar) split the cost;
//!   `full_batched` is what the ingest runs (`fk::forward_frames`, four frames per SIMD
//!   batch) and `full_libm` the libm FK it replaced. The `full_proposal_*`
//!   prototypes of the results below were removed once issue 15 put proposal 4 in the
//!   library (`skeleton::fk::simd`): the bench no longer keeps a copy of the FK.
//! - `ingest`: `ingest::ingest` of the whole clip (lead-in, units, FK, COM, SG filter,
//!   floors, contacts, flights), frames/s.
//!
//! # Results
//! 2026-11-29, 2-core x86_64 sandbox (KVM, Xeon with AVX2/FMA/AVX-512; shared and noisy,
//! ±10 % between runs), release profile, criterion 0.5, cmu_01_01 (2752 frames):
//!
//! ```text
//! parse/parse_reader                      4.95 ms    399 MiB/s
//! parse/baseline_split_parse              3.89 ms    508 MiB/s   parse_reader 1.27× slower
//!                                                               (1.35× in a second run): < 2×
//! fk_com/full                             3.68 ms    748 k frames/s   floor 0.5 M met, goal 1.5 M not
//! fk_com/fk_only                          3.40 ms    809 k frames/s   FK is 92 % of `full`
//! fk_com/units_com_only                   0.21 ms   13.0 M frames/s
//! fk_com/trig_only                        1.80 ms   1.53 M frames/s   93 libm sin_cos a frame:
//!                                                                     half of FK
//! fk_com/trig_only_poly                   2.35 ms   1.17 M frames/s   scalar polynomial: no gain
//! fk_com/full_proposal_1_const_axis       2.92 ms    942 k frames/s   +26 %
//! fk_com/full_proposal_2_batched_trig     1.87 ms   1.47 M frames/s   +97 % (AVX2+FMA batch)
//! fk_com/full_proposal_3_padded_avx2      2.41 ms   1.14 M frames/s   whole FK as AVX2: worse than 2
//! fk_com/full_proposal_4_four_frames_per_lane
//!                                         1.57 ms   1.76 M frames/s   goal met
//! ingest/ingest                           5.91 ms    466 k frames/s   whole clip, every stage
//! ```
//!
//! After `fk::rotate_right` took proposal 1 (constant column indices), same machine:
//!
//! ```text
//! fk_com/full                             3.23 ms    852 k frames/s   +14 %
//! fk_com/fk_only                          2.97 ms    925 k frames/s
//! ingest/ingest                           5.48 ms    502 k frames/s
//! parse/parse_reader                      4.96 ms    398 MiB/s  (baseline 504 MiB/s: 1.27×)
//! ```
//! Proposals 2 and 4 (AVX2 batched sin/cos, four frames per lane) reach the 1.5 M goal but
//! add a runtime-dispatched SIMD path; not adopted yet.
//!
//! Issue 15 adopted proposal 4 (`fk::forward_frames`, module `skeleton::fk::simd`).
//! 2026-12-02, same machine (load ≈ 1), profiling profile, `--measurement-time 4`:
//!
//! ```text
//! fk_com/full_batched                     1.40 ms   1.96 M frames/s   what the ingest runs
//! fk_com/full_libm                        3.09 ms    890 k frames/s   the FK before issue 15 (then `full_libm_reference`)
//! fk_com/full                             3.19 ms    863 k frames/s   one frame per call
//! fk_com/full_proposal_4_four_frames_per_lane  1.36 ms  2.03 M frames/s   (prototype, since removed)
//! ```
//! `perf` of `full`: 52 % in `fk::forward` itself, 39 % in glibc `__sincos_fma`, 3 % in
//! `com::com`. Inside `fk::forward` the hot spots are the reloads of the rotation matrix
//! that `rotate_right` keeps on the stack: it indexes columns with the runtime pair
//! `(a, b)` from `match axis`, so the matrix cannot live in registers, and its 8-byte
//! stores followed by 16-byte loads defeat store-to-load forwarding (≈ 30 % of the
//! function's samples on two loads). Variant 1 fixes only that (const-generic column
//! indices per axis arm); variant 2 adds one branch-free, vectorisable sin/cos pass over
//! the frame's 93 angles (`sincos_deg`, exact reduction by 90°, Taylor 15/16, ≤ 4e-16
//! from libm) compiled for AVX2+FMA behind a runtime check; variant 4 runs four frames
//! per call, one per SIMD lane. Building each local rotation off the dependency chain and
//! then one `parent · local` product was 15–20 % slower than variant 1 and was dropped.

mod parse_limit;

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use stancelib::bvh::{self, Bvh};
use stancelib::ingest::{ingest, IngestOptions};
use stancelib::skeleton::com::{com, BodyPoints, Sex, SidePoints};
use stancelib::skeleton::fk::{self, FkWorkspace};
use stancelib::skeleton::landmarks::{self, Landmarks, Limb, Mapping};
use stancelib::skeleton::units::CMU_UNIT_M;
use stancelib::skeleton::Skeleton;

use parse_limit::baseline_split_parse;

/// The benchmarked clip, relative to the crate root.
const CLIP: &str = "../shared/data/bvh/jump/cmu_01_01_forward_jumps_mb.bvh";
/// Frames of the synthetic stand-in (the real clip's count).
const SYNTH_FRAMES: usize = 2752;

/// The clip's bytes and a label: `$STAGES_CLIP` when set (a path, or `synthetic`), else
/// [`CLIP`], else (no `../shared`) a synthetic clip.
fn clip_bytes() -> (Vec<u8>, String) {
    let synthetic = || {
        (
            make_clip(SYNTH_FRAMES, 0x5eed).into_bytes(),
            "synthetic_31j".to_string(),
        )
    };
    let p = match std::env::var("STAGES_CLIP") {
        Ok(s) if s == "synthetic" => return synthetic(),
        Ok(s) => PathBuf::from(s),
        Err(_) => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(CLIP),
    };
    match std::fs::read(&p) {
        Ok(b) => {
            let stem = p
                .file_stem()
                .map_or("clip".into(), |s| s.to_string_lossy().into_owned());
            (b, stem)
        }
        Err(e) => {
            eprintln!(
                "stages: {} not readable ({e}); benchmarking a synthetic clip \
                 ({SYNTH_FRAMES} frames, 31 joints) instead",
                p.display()
            );
            synthetic()
        }
    }
}

// ---------------------------------------------------------------------------------------
// Synthetic stand-in: the CMU "mb" 31-joint skeleton with seeded random angles.

/// (name, parent index, OFFSET, End Site) of one joint.
type JointSpec = (&'static str, Option<usize>, [f64; 3], Option<[f64; 3]>);

/// The CMU mb skeleton, in file order.
#[rustfmt::skip]
const CMU_MB: [JointSpec; 31] = [
    ("Hips", None, [0.0, 0.0, 0.0], None),
    ("LHipJoint", Some(0), [0.0, 0.0, 0.0], None),
    ("LeftUpLeg", Some(1), [1.36306, -1.79463, 0.83929], None),
    ("LeftLeg", Some(2), [2.44811, -6.72613, 0.0], None),
    ("LeftFoot", Some(3), [2.56220, -7.03959, 0.0], None),
    ("LeftToeBase", Some(4), [0.15764, -0.43311, 2.32255], Some([0.0, 0.0, 1.18966])),
    ("RHipJoint", Some(0), [0.0, 0.0, 0.0], None),
    ("RightUpLeg", Some(6), [-1.30552, -1.79463, 0.83929], None),
    ("RightLeg", Some(7), [-2.54253, -6.98555, 0.0], None),
    ("RightFoot", Some(8), [-2.56826, -7.05623, 0.0], None),
    ("RightToeBase", Some(9), [-0.16473, -0.45259, 2.36315], Some([0.0, 0.0, 1.21082])),
    ("LowerBack", Some(0), [0.0, 0.0, 0.0], None),
    ("Spine", Some(11), [0.02827, 2.03559, -0.19338], None),
    ("Spine1", Some(12), [0.05672, 2.04885, -0.04275], None),
    ("Neck", Some(13), [0.0, 0.0, 0.0], None),
    ("Neck1", Some(14), [-0.05417, 1.74624, 0.17202], None),
    ("Head", Some(15), [0.10407, 1.76136, -0.12397], Some([0.03720, 1.77044, -0.06241])),
    ("LeftShoulder", Some(13), [0.0, 0.0, 0.0], None),
    ("LeftArm", Some(17), [3.36241, 1.20089, -0.31121], None),
    ("LeftForeArm", Some(18), [4.98300, 0.0, 0.0], None),
    ("LeftHand", Some(19), [3.48356, 0.0, 0.0], None),
    ("LeftFingerBase", Some(20), [0.0, 0.0, 0.0], None),
    ("LeftHandIndex1", Some(21), [0.71526, 0.0, 0.0], Some([0.57666, 0.0, 0.0])),
    ("LThumb", Some(20), [0.0, 0.0, 0.0], Some([0.58547, 0.0, 0.58547])),
    ("RightShoulder", Some(13), [0.0, 0.0, 0.0], None),
    ("RightArm", Some(24), [-3.13660, 1.37405, -0.40465], None),
    ("RightForeArm", Some(25), [-5.24190, 0.0, 0.0], None),
    ("RightHand", Some(26), [-3.44417, 0.0, 0.0], None),
    ("RightFingerBase", Some(27), [0.0, 0.0, 0.0], None),
    ("RightHandIndex1", Some(28), [-0.62253, 0.0, 0.0], Some([-0.50190, 0.0, 0.0])),
    ("RThumb", Some(27), [0.0, 0.0, 0.0], Some([-0.50956, 0.0, 0.50956])),
];

/// A BVH text of `n_frames` frames on the 31-joint CMU mb skeleton: a walk-like root path
/// and seeded angles within ±30° (xorshift64, `seed`), 4 decimals like the CMU files.
fn make_clip(n_frames: usize, seed: u64) -> String {
    use std::fmt::Write;
    let mut s = String::from("HIERARCHY\n");
    let mut depth = 0;
    let mut open: Vec<usize> = Vec::new();
    for (i, (name, parent, off, _)) in CMU_MB.iter().enumerate() {
        while open.last().is_some_and(|&j| Some(j) != *parent) {
            let j = open.pop().unwrap();
            depth -= 1;
            close_joint(&mut s, depth, CMU_MB[j].3);
        }
        let ind = "\t".repeat(depth);
        let kw = if parent.is_none() { "ROOT" } else { "JOINT" };
        let ch = if parent.is_none() {
            "6 Xposition Yposition Zposition Zrotation Yrotation Xrotation"
        } else {
            "3 Zrotation Yrotation Xrotation"
        };
        let _ = write!(
            s,
            "{ind}{kw} {name}\n{ind}{{\n{ind}\tOFFSET {} {} {}\n{ind}\tCHANNELS {ch}\n",
            off[0], off[1], off[2]
        );
        open.push(i);
        depth += 1;
    }
    while let Some(j) = open.pop() {
        depth -= 1;
        close_joint(&mut s, depth, CMU_MB[j].3);
    }
    let _ = write!(s, "MOTION\nFrames: {n_frames}\nFrame Time: .0083333\n");
    let mut x = seed | 1;
    let mut rnd = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    for f in 0..n_frames {
        let t = f as f64 / 120.0;
        let _ = write!(
            s,
            "{:.4} {:.4} {:.4}",
            1.4 / CMU_UNIT_M * t,
            17.0 + 0.3 * (6.0 * t).sin(),
            0.0
        );
        for _ in 3..96 {
            let _ = write!(s, " {:.4}", 60.0 * rnd() - 30.0);
        }
        s.push('\n');
    }
    s
}

fn close_joint(s: &mut String, depth: usize, end: Option<[f64; 3]>) {
    let ind = "\t".repeat(depth);
    if let Some(e) = end {
        s.push_str(&format!(
            "{ind}\tEnd Site\n{ind}\t{{\n{ind}\t\tOFFSET {} {} {}\n{ind}\t}}\n",
            e[0], e[1], e[2]
        ));
    }
    s.push_str(&format!("{ind}}}\n"));
}

// ---------------------------------------------------------------------------------------
// (a) parse

fn bench_parse(c: &mut Criterion) {
    let (bytes, label) = clip_bytes();
    let ours = bvh::parse_reader(&bytes[..]).expect("clip parses");
    assert_eq!(
        baseline_split_parse(&bytes),
        ours.motion.values,
        "baseline and parser disagree"
    );
    let mut g = c.benchmark_group("parse");
    g.throughput(Throughput::Bytes(bytes.len() as u64));
    g.bench_with_input(
        BenchmarkId::new("parse_reader", &label),
        &bytes,
        |b, bytes| b.iter(|| bvh::parse_reader(black_box(&bytes[..])).unwrap()),
    );
    g.bench_with_input(
        BenchmarkId::new("baseline_split_parse", &label),
        &bytes,
        |b, bytes| b.iter(|| baseline_split_parse(black_box(bytes))),
    );
    g.finish();
}

// ---------------------------------------------------------------------------------------
// (b) fk_com

/// Everything built once per clip: the model, the landmarks, the FK scratch, and the
/// point indices the per-frame loop reads.
struct Prepared {
    bvh: Bvh,
    skel: Skeleton,
    lm: Landmarks,
    /// Toe-tip point (the toe joint's End Site), left and right.
    ttip: [usize; 2],
}

fn prepare(bytes: &[u8]) -> Prepared {
    let bvh = bvh::parse_reader(bytes).expect("clip parses");
    let skel = Skeleton::from_bvh(&bvh);
    let rest = fk::rest_pose(&skel);
    let lm = match landmarks::map(&skel, &rest, &BTreeMap::new()).expect("landmarks") {
        Mapping::Found(lm) => lm,
        Mapping::NotABody => panic!("the benchmark clip is a body"),
    };
    let tip = |l: &Limb| {
        skel.end_site_point(l.toe_joint.expect("toe joint"))
            .expect("toe End Site")
    };
    let ttip = [tip(&lm.left), tip(&lm.right)];
    Prepared {
        bvh,
        skel,
        lm,
        ttip,
    }
}

/// File-frame point (Y up, CMU units) → internal Z-up metres.
#[inline(always)]
fn to_internal_m(p: [f64; 3]) -> [f64; 3] {
    [p[0] * CMU_UNIT_M, -p[2] * CMU_UNIT_M, p[1] * CMU_UNIT_M]
}

fn side(l: &Limb, ttip: usize, pts: &[[f64; 3]]) -> SidePoints {
    SidePoints {
        hjc: pts[l.hip],
        kjc: pts[l.knee],
        ajc: pts[l.ankle],
        ttip: pts[ttip],
        arm: l
            .arm
            .as_ref()
            .map(|a| [pts[a.shoulder], pts[a.elbow], pts[a.wrist], a.met3.at(pts)]),
    }
}

/// Units, landmarks and COM of one frame from its file-frame points; writes the Z-up
/// metre points into `pts_m` and returns the COM.
#[inline(always)]
fn units_com(p: &Prepared, pts: &[[f64; 3]], pts_m: &mut [[f64; 3]]) -> [f64; 3] {
    for (m, f) in pts_m.iter_mut().zip(pts) {
        *m = to_internal_m(*f);
    }
    let body = BodyPoints {
        vert: p.lm.vert.at(pts_m),
        cerv: pts_m[p.lm.cerv],
        left: side(&p.lm.left, p.ttip[0], pts_m),
        right: side(&p.lm.right, p.ttip[1], pts_m),
    };
    com(&body, Sex::Male)
}

/// The contact points of spec com-from-bvh §7.3: toe tip and ankle, left then right.
#[inline(always)]
fn contact_points(p: &Prepared, pts_m: &[[f64; 3]]) -> [[f64; 3]; 4] {
    [
        pts_m[p.ttip[0]],
        pts_m[p.lm.left.ankle],
        pts_m[p.ttip[1]],
        pts_m[p.lm.right.ankle],
    ]
}

/// The timed loop: every frame → points (file frame and Z-up metres), contact points
/// (toe tips and ankles, here read back into `contacts`) and the COM.
fn fk_com_all(
    p: &Prepared,
    ws: &mut FkWorkspace,
    pts: &mut [[f64; 3]],
    pts_m: &mut [[f64; 3]],
    out: &mut Vec<[f64; 3]>,
    contacts: &mut Vec<[[f64; 3]; 4]>,
) {
    out.clear();
    contacts.clear();
    let m = &p.bvh.motion;
    for f in 0..m.n_frames() {
        fk::forward(&p.skel, ws, m.row(f), pts);
        out.push(units_com(p, pts, pts_m));
        contacts.push(contact_points(p, pts_m));
    }
}

fn bench_fk_com(c: &mut Criterion) {
    let (bytes, label) = clip_bytes();
    let p = prepare(&bytes);
    let n = p.bvh.motion.n_frames();
    let np = p.skel.n_points();
    let mut ws = FkWorkspace::new(&p.skel);
    let mut pts = vec![[0.0; 3]; np];
    let mut pts_m = vec![[0.0; 3]; np];
    let mut out = Vec::with_capacity(n);
    let mut contacts = Vec::with_capacity(n);
    // Sanity: a standing CMU subject's COM is about 0.9–1.1 m up.
    fk_com_all(&p, &mut ws, &mut pts, &mut pts_m, &mut out, &mut contacts);
    let z = out[n / 2][2];
    assert!(z > 0.4 && z < 2.5, "COM height {z} m is implausible");

    let mut g = c.benchmark_group("fk_com");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function(BenchmarkId::new("full", &label), |b| {
        b.iter(|| {
            fk_com_all(&p, &mut ws, &mut pts, &mut pts_m, &mut out, &mut contacts);
            black_box((&out, &contacts));
        })
    });
    // What ingest runs: `fk::forward_frames` over every frame (FK_LANES frames per SIMD
    // batch), then units, contact points and COM per frame.
    let rows = &p.bvh.motion.values;
    let mut all = vec![[0.0; 3]; n * np];
    g.bench_function(BenchmarkId::new("full_batched", &label), |b| {
        b.iter(|| {
            fk::forward_frames(&p.skel, &mut ws, black_box(rows), &mut all);
            out.clear();
            contacts.clear();
            for fp in all.chunks_exact(np) {
                out.push(units_com(&p, fp, &mut pts_m));
                contacts.push(contact_points(&p, &pts_m));
            }
            black_box((&out, &contacts));
        })
    });
    // The libm FK `fk::forward` ran before issue 15 (`fk::forward_libm`).
    let mut rot = vec![fk::IDENTITY; p.skel.n_joints()];
    g.bench_function(BenchmarkId::new("full_libm", &label), |b| {
        b.iter(|| {
            let m = &p.bvh.motion;
            out.clear();
            contacts.clear();
            for f in 0..n {
                fk::forward_libm(&p.skel, &mut rot, black_box(m.row(f)), &mut pts);
                out.push(units_com(&p, &pts, &mut pts_m));
                contacts.push(contact_points(&p, &pts_m));
            }
            black_box((&out, &contacts));
        })
    });
    // Diagnosis: FK alone (trig + matrix products), units + COM alone (given the points),
    // and the trig floor (one sin_cos per rotation channel).
    g.bench_function(BenchmarkId::new("fk_only", &label), |b| {
        b.iter(|| {
            let m = &p.bvh.motion;
            for f in 0..n {
                fk::forward(&p.skel, &mut ws, black_box(m.row(f)), &mut pts);
            }
            black_box(&pts);
        })
    });
    let all_pts: Vec<Vec<[f64; 3]>> = (0..n)
        .map(|f| {
            fk::forward(&p.skel, &mut ws, p.bvh.motion.row(f), &mut pts);
            pts.clone()
        })
        .collect();
    g.bench_function(BenchmarkId::new("units_com_only", &label), |b| {
        b.iter(|| {
            let mut acc = [0.0; 3];
            for fp in &all_pts {
                let c = units_com(&p, black_box(fp), &mut pts_m);
                acc = [acc[0] + c[0], acc[1] + c[1], acc[2] + c[2]];
            }
            black_box(acc)
        })
    });
    let rot_idx: Vec<usize> = p
        .skel
        .channels
        .iter()
        .flat_map(|c| c.rotations.iter().map(|r| r.1))
        .collect();
    g.bench_function(BenchmarkId::new("trig_only", &label), |b| {
        b.iter(|| {
            let m = &p.bvh.motion;
            let mut acc = 0.0;
            for f in 0..n {
                let row = black_box(m.row(f));
                for &i in &rot_idx {
                    let (s, c) = row[i].to_radians().sin_cos();
                    acc += s + c;
                }
            }
            black_box(acc)
        })
    });
    g.bench_function(BenchmarkId::new("trig_only_poly", &label), |b| {
        b.iter(|| {
            let m = &p.bvh.motion;
            let mut acc = 0.0;
            for f in 0..n {
                let row = black_box(m.row(f));
                for &i in &rot_idx {
                    let (s, c) = stancelib::math::trig::sincos_deg(row[i]);
                    acc += s + c;
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

// ---------------------------------------------------------------------------------------
// (c) ingest

fn bench_ingest(c: &mut Criterion) {
    let (bytes, label) = clip_bytes();
    let bvh = bvh::parse_reader(&bytes[..]).expect("clip parses");
    let opts = IngestOptions::default();
    ingest(&bvh, &opts).expect("clip ingests");
    let mut g = c.benchmark_group("ingest");
    g.sample_size(20).measurement_time(Duration::from_secs(10));
    g.throughput(Throughput::Elements(bvh.motion.n_frames() as u64));
    g.bench_function(BenchmarkId::new("ingest", &label), |b| {
        b.iter(|| ingest(black_box(&bvh), &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench_parse, bench_fk_com, bench_ingest);
criterion_main!(benches);
