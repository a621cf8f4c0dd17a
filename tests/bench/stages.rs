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
//!   channel) and `trig_only_poly` (`proposal::sincos_deg`, scalar) split the cost;
//!   `full_proposal_*` are `full` with the FK changes prototyped in module `proposal`
//!   (cumulative; each is checked against `fk::forward` before it is timed).
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
//! fk_com/full_libm_reference              3.09 ms    890 k frames/s   the FK before issue 15
//! fk_com/full                             3.19 ms    863 k frames/s   one frame per call
//! fk_com/full_proposal_4_four_frames_per_lane  1.36 ms  2.03 M frames/s
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
    // The libm FK `fk::forward` ran before issue 15 (`fk::forward_reference`).
    let mut rot = vec![fk::IDENTITY; p.skel.n_joints()];
    g.bench_function(BenchmarkId::new("full_libm_reference", &label), |b| {
        b.iter(|| {
            let m = &p.bvh.motion;
            out.clear();
            contacts.clear();
            for f in 0..n {
                fk::forward_reference(&p.skel, &mut rot, black_box(m.row(f)), &mut pts);
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
    // The proposed changes (module `proposal`), cumulatively, each checked against
    // `fk::forward` before it is timed.
    let mut flat = proposal::FlatFk::new(&p.skel);
    let mut padded = proposal::Padded::new(&p.skel);
    type Fk = fn(&Skeleton, &mut proposal::FlatFk, &mut proposal::Padded, &[f64], &mut [[f64; 3]]);
    let variants: [(&str, Fk); 3] = [
        ("full_proposal_1_const_axis", |s, w, _, r, p| {
            proposal::forward::<false>(s, w, r, p)
        }),
        ("full_proposal_2_batched_trig", |s, w, _, r, p| {
            proposal::forward::<true>(s, w, r, p)
        }),
        ("full_proposal_3_padded_avx2", proposal::forward_padded),
    ];
    let mut pts2 = pts.clone();
    for (name, fwd) in variants {
        let mut worst: f64 = 0.0;
        for f in 0..n {
            fk::forward(&p.skel, &mut ws, p.bvh.motion.row(f), &mut pts);
            fwd(
                &p.skel,
                &mut flat,
                &mut padded,
                p.bvh.motion.row(f),
                &mut pts2,
            );
            for (a, b) in pts.iter().zip(&pts2) {
                worst = (0..3).fold(worst, |w, k| w.max((a[k] - b[k]).abs()));
            }
        }
        eprintln!("fk_com: {name} vs fk::forward: largest point difference {worst:.1e} file units");
        assert!(worst < 1e-9, "{name} disagrees with fk::forward by {worst}");
        g.bench_function(BenchmarkId::new(name, &label), |b| {
            b.iter(|| {
                let m = &p.bvh.motion;
                out.clear();
                contacts.clear();
                for f in 0..n {
                    fwd(&p.skel, &mut flat, &mut padded, m.row(f), &mut pts);
                    out.push(units_com(&p, &pts, &mut pts_m));
                    contacts.push(contact_points(&p, &pts_m));
                }
                black_box((&out, &contacts));
            })
        });
    }
    // Variant 4: four frames per call (the tail, n mod 4 frames, through `fk::forward`).
    let mut x4 = proposal::X4::new(&p.skel, &flat);
    let mut quad = vec![vec![[0.0; 3]; np]; 4];
    let (mut ws4, mut pts4, mut pts4_m) = (FkWorkspace::new(&p.skel), pts.clone(), pts_m.clone());
    let mut fk_com_x4 = |out: &mut Vec<[f64; 3]>, contacts: &mut Vec<[[f64; 3]; 4]>| {
        let m = &p.bvh.motion;
        out.clear();
        contacts.clear();
        let mut f = 0;
        while f + 4 <= n {
            let [q0, q1, q2, q3] = &mut quad[..] else {
                unreachable!()
            };
            let rows = [m.row(f), m.row(f + 1), m.row(f + 2), m.row(f + 3)];
            proposal::forward_x4(&p.skel, &flat, &mut x4, rows, [q0, q1, q2, q3]);
            for q in &quad {
                out.push(units_com(&p, q, &mut pts4_m));
                contacts.push(contact_points(&p, &pts4_m));
            }
            f += 4;
        }
        for f in f..n {
            fk::forward(&p.skel, &mut ws4, m.row(f), &mut pts4);
            out.push(units_com(&p, &pts4, &mut pts4_m));
            contacts.push(contact_points(&p, &pts4_m));
        }
    };
    let (mut out2, mut contacts2) = (Vec::new(), Vec::new());
    fk_com_x4(&mut out2, &mut contacts2);
    fk_com_all(&p, &mut ws, &mut pts, &mut pts_m, &mut out, &mut contacts);
    let flat_pts = |o: &[[f64; 3]], c: &[[[f64; 3]; 4]]| -> Vec<f64> {
        o.iter()
            .flatten()
            .chain(c.iter().flatten().flatten())
            .copied()
            .collect()
    };
    let (a, b) = (flat_pts(&out, &contacts), flat_pts(&out2, &contacts2));
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "fk_com: full_proposal_4_four_frames_per_lane vs fk::forward: \
         largest COM or contact point difference {worst:.1e} m"
    );
    assert!(
        a.len() == b.len() && worst < 1e-9,
        "variant 4 disagrees with fk::forward by {worst}"
    );
    g.bench_function(
        BenchmarkId::new("full_proposal_4_four_frames_per_lane", &label),
        |b| {
            b.iter(|| {
                fk_com_x4(&mut out2, &mut contacts2);
                black_box((&out2, &contacts2));
            })
        },
    );
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
                    let (s, c) = proposal::sincos_deg(row[i]);
                    acc += s + c;
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

// ---------------------------------------------------------------------------------------
// Prototype of the change proposed for `fk::forward` (diagnosis only, not used by the
// library): the frame's rotation angles are gathered once, their sines and cosines are
// computed in one branch-free loop (`sincos_deg`) instead of one libm `sin_cos` call per
// channel, then the same column-mixing products run.

mod proposal {
    use stancelib::skeleton::fk::{mul_vec, Mat3, IDENTITY};
    use stancelib::skeleton::model::TranslationMode;
    use stancelib::skeleton::Skeleton;

    /// 1.5·2⁵²: adding it rounds a double of magnitude < 2⁵¹ to an integer.
    const ROUND_MAGIC: f64 = 6755399441055744.0;

    /// sin and cos of `x` degrees. Reduction by the nearest multiple of 90° (exact for
    /// |x| < 2⁴⁴), then Taylor polynomials of degree 15 and 16 on r ∈ [−π/4, π/4]
    /// (truncation < 5e-17); the quadrant swaps and negates, branch-free so that a loop
    /// over many angles vectorises. Agrees with libm to ≤ 4e-16 on the CMU clips and
    /// gives exact 0 and ±1 at multiples of 90°.
    #[inline(always)]
    pub fn sincos_deg(x: f64) -> (f64, f64) {
        let k = x * (1.0 / 90.0) + ROUND_MAGIC;
        let quad = k.to_bits() & 3;
        let r = (x - (k - ROUND_MAGIC) * 90.0) * (std::f64::consts::PI / 180.0);
        let r2 = r * r;
        #[rustfmt::skip]
        let s = r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0
            + r2 * (1.0 / 362880.0 + r2 * (-1.0 / 39916800.0 + r2 * (1.0 / 6227020800.0
            + r2 * (-1.0 / 1307674368000.0)))))));
        #[rustfmt::skip]
        let c = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0
            + r2 * (1.0 / 40320.0 + r2 * (-1.0 / 3628800.0 + r2 * (1.0 / 479001600.0
            + r2 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0))))))));
        let swap = quad & 1 == 1;
        let (s1, c1) = (if swap { c } else { s }, if swap { s } else { c });
        let sn = if quad & 2 != 0 { -s1 } else { s1 };
        let cn = if (quad + 1) & 2 != 0 { -c1 } else { c1 };
        (sn, cn)
    }

    #[inline(always)]
    fn sincos_all_body(a: &[f64], s: &mut [f64], c: &mut [f64]) {
        let n = a.len().min(s.len()).min(c.len());
        for i in 0..n {
            (s[i], c[i]) = sincos_deg(a[i]);
        }
    }

    /// The batch compiled for AVX2 + FMA (4 angles per instruction).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn sincos_all_avx2(a: &[f64], s: &mut [f64], c: &mut [f64]) {
        sincos_all_body(a, s, c)
    }

    /// sin and cos of every angle (degrees), dispatched once on the CPU's features.
    #[inline]
    pub fn sincos_all(avx2: bool, a: &[f64], s: &mut [f64], c: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: `avx2` is true only when the CPU reports AVX2 and FMA (`FlatFk::new`).
            return unsafe { sincos_all_avx2(a, s, c) };
        }
        let _ = avx2;
        sincos_all_body(a, s, c)
    }

    /// Flat channel tables built once per skeleton, plus per-frame scratch.
    pub struct FlatFk {
        /// Row index of every rotation channel, joints in order.
        rot_idx: Vec<usize>,
        /// Axis of every rotation channel.
        rot_axis: Vec<u8>,
        /// Range of `rot_idx` per joint.
        joint_rot: Vec<(usize, usize)>,
        angles: Vec<f64>,
        sin: Vec<f64>,
        cos: Vec<f64>,
        /// World rotation per joint.
        rot: Vec<Mat3>,
        /// The CPU has AVX2 and FMA.
        avx2: bool,
    }

    impl FlatFk {
        pub fn new(skel: &Skeleton) -> FlatFk {
            let (mut rot_idx, mut rot_axis, mut joint_rot) = (Vec::new(), Vec::new(), Vec::new());
            for ch in &skel.channels {
                let start = rot_idx.len();
                for &(axis, idx) in &ch.rotations {
                    rot_idx.push(idx);
                    rot_axis.push(axis as u8);
                }
                joint_rot.push((start, rot_idx.len()));
            }
            let n = rot_idx.len();
            #[cfg(target_arch = "x86_64")]
            let avx2 = is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
            #[cfg(not(target_arch = "x86_64"))]
            let avx2 = false;
            FlatFk {
                rot_idx,
                rot_axis,
                joint_rot,
                angles: vec![0.0; n],
                sin: vec![0.0; n],
                cos: vec![0.0; n],
                rot: vec![IDENTITY; skel.n_joints()],
                avx2,
            }
        }
    }

    /// `fk::rotate_right` with the sine and cosine given, and constant column indices in
    /// each arm so that the matrix stays in registers (with `m[a]`, `m[b]` for runtime
    /// `a`, `b` it lives on the stack, and its scalar stores followed by 16-byte loads
    /// defeat store-to-load forwarding).
    #[inline(always)]
    fn rotate_right_sc(m: &mut Mat3, axis: u8, s: f64, c: f64) {
        #[inline(always)]
        fn mix<const A: usize, const B: usize>(m: &mut Mat3, s: f64, c: f64) {
            let (ca, cb) = (m[A], m[B]);
            for r in 0..3 {
                m[A][r] = c * ca[r] + s * cb[r];
                m[B][r] = -s * ca[r] + c * cb[r];
            }
        }
        match axis {
            0 => mix::<1, 2>(m, s, c),
            1 => mix::<2, 0>(m, s, c),
            _ => mix::<0, 1>(m, s, c),
        }
    }

    /// Same output as `fk::forward` (to rounding). Changes:
    /// - constant column indices in the per-channel rotation (`rotate_right_sc`);
    /// - `BATCH`: one batched sin/cos pass over the frame's rotation channels
    ///   (`sincos_all`) instead of one libm `sin_cos` call per channel.
    ///
    /// (Also tried and dropped: building each joint's local rotation first, off the
    /// parent-to-child dependency chain, then one `parent · local` product. It was 15–20 %
    /// slower than mixing the parent's columns in place: 27 multiply-adds instead of 18.)
    pub fn forward<const BATCH: bool>(
        skel: &Skeleton,
        w: &mut FlatFk,
        row: &[f64],
        points: &mut [[f64; 3]],
    ) {
        assert!(row.len() >= skel.n_channels && points.len() >= skel.n_points());
        for (a, &i) in w.angles.iter_mut().zip(&w.rot_idx) {
            *a = row[i];
        }
        if BATCH {
            sincos_all(w.avx2, &w.angles, &mut w.sin, &mut w.cos);
        } else {
            for ((a, s), c) in w.angles.iter().zip(w.sin.iter_mut()).zip(w.cos.iter_mut()) {
                (*s, *c) = a.to_radians().sin_cos();
            }
        }
        for j in 0..skel.n_joints() {
            let ch = &skel.channels[j];
            let off = skel.offsets[j];
            let t: [f64; 3] = match ch.mode {
                TranslationMode::Offset => off,
                TranslationMode::Replace => {
                    std::array::from_fn(|a| ch.translations[a].map_or(off[a], |i| row[i]))
                }
                TranslationMode::Delta => {
                    std::array::from_fn(|a| off[a] + ch.translations[a].map_or(0.0, |i| row[i]))
                }
            };
            let (k0, k1) = w.joint_rot[j];
            let (rp, p) = match skel.parents[j] {
                None => (IDENTITY, t),
                Some(pj) => {
                    let rp = w.rot[pj];
                    let d = mul_vec(&rp, &t);
                    let pp = points[pj];
                    (rp, [pp[0] + d[0], pp[1] + d[1], pp[2] + d[2]])
                }
            };
            let mut r = rp;
            for k in k0..k1 {
                rotate_right_sc(&mut r, w.rot_axis[k], w.sin[k], w.cos[k]);
            }
            w.rot[j] = r;
            points[j] = p;
        }
        let nj = skel.n_joints();
        for (e, (j, off)) in skel.end_sites.iter().enumerate() {
            let d = mul_vec(&w.rot[*j], off);
            let p = points[*j];
            points[nj + e] = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
        }
    }
    /// A column padded to 4 lanes (one AVX register).
    type Col = [f64; 4];
    /// A rotation as three padded columns.
    type M4 = [Col; 3];
    const I4: M4 = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];

    #[inline(always)]
    fn lin2(a: f64, x: &Col, b: f64, y: &Col) -> Col {
        std::array::from_fn(|r| a * x[r] + b * y[r])
    }

    #[inline(always)]
    fn mul_vec4(m: &M4, v: &Col) -> Col {
        std::array::from_fn(|r| m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2])
    }

    #[inline(always)]
    fn rotate4(m: &mut M4, axis: u8, s: f64, c: f64) {
        #[inline(always)]
        fn mix<const A: usize, const B: usize>(m: &mut M4, s: f64, c: f64) {
            let (ca, cb) = (m[A], m[B]);
            m[A] = lin2(c, &ca, s, &cb);
            m[B] = lin2(-s, &ca, c, &cb);
        }
        match axis {
            0 => mix::<1, 2>(m, s, c),
            1 => mix::<2, 0>(m, s, c),
            _ => mix::<0, 1>(m, s, c),
        }
    }

    /// Scratch of [`forward_padded`]: world rotation and position per joint, padded.
    pub struct Padded {
        rot: Vec<M4>,
        pos: Vec<Col>,
    }

    impl Padded {
        pub fn new(skel: &Skeleton) -> Padded {
            Padded {
                rot: vec![I4; skel.n_joints()],
                pos: vec![[0.0; 4]; skel.n_joints()],
            }
        }
    }

    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // `j` indexes seven parallel arrays
    fn forward_padded_body(
        skel: &Skeleton,
        w: &mut FlatFk,
        pd: &mut Padded,
        row: &[f64],
        points: &mut [[f64; 3]],
    ) {
        for (a, &i) in w.angles.iter_mut().zip(&w.rot_idx) {
            *a = row[i];
        }
        sincos_all_body(&w.angles, &mut w.sin, &mut w.cos);
        for j in 0..skel.n_joints() {
            let ch = &skel.channels[j];
            let off = skel.offsets[j];
            let t: Col = match ch.mode {
                TranslationMode::Offset => [off[0], off[1], off[2], 0.0],
                TranslationMode::Replace => std::array::from_fn(|a| {
                    if a < 3 {
                        ch.translations[a].map_or(off[a], |i| row[i])
                    } else {
                        0.0
                    }
                }),
                TranslationMode::Delta => std::array::from_fn(|a| {
                    if a < 3 {
                        off[a] + ch.translations[a].map_or(0.0, |i| row[i])
                    } else {
                        0.0
                    }
                }),
            };
            let (k0, k1) = w.joint_rot[j];
            let (rp, p) = match skel.parents[j] {
                None => (I4, t),
                Some(pj) => {
                    let rp = pd.rot[pj];
                    let d = mul_vec4(&rp, &t);
                    let pp = pd.pos[pj];
                    (rp, std::array::from_fn(|r| pp[r] + d[r]))
                }
            };
            let mut r = rp;
            for k in k0..k1 {
                rotate4(&mut r, w.rot_axis[k], w.sin[k], w.cos[k]);
            }
            pd.rot[j] = r;
            pd.pos[j] = p;
            points[j] = [p[0], p[1], p[2]];
        }
        let nj = skel.n_joints();
        for (e, (j, off)) in skel.end_sites.iter().enumerate() {
            let d = mul_vec4(&pd.rot[*j], &[off[0], off[1], off[2], 0.0]);
            let p = pd.pos[*j];
            points[nj + e] = [p[0] + d[0], p[1] + d[1], p[2] + d[2]];
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn forward_padded_avx2(
        skel: &Skeleton,
        w: &mut FlatFk,
        pd: &mut Padded,
        row: &[f64],
        points: &mut [[f64; 3]],
    ) {
        forward_padded_body(skel, w, pd, row, points)
    }

    /// Variant 3: batched trig, and the whole FK compiled for AVX2 + FMA (runtime check)
    /// with rotations and positions kept as 4-lane padded columns, so that every column
    /// is one register, loaded and stored whole (no split stores that a child's load
    /// cannot forward from).
    pub fn forward_padded(
        skel: &Skeleton,
        w: &mut FlatFk,
        pd: &mut Padded,
        row: &[f64],
        points: &mut [[f64; 3]],
    ) {
        assert!(row.len() >= skel.n_channels && points.len() >= skel.n_points());
        #[cfg(target_arch = "x86_64")]
        if w.avx2 {
            // SAFETY: `avx2` is true only when the CPU reports AVX2 and FMA (`FlatFk::new`).
            return unsafe { forward_padded_avx2(skel, w, pd, row, points) };
        }
        forward_padded_body(skel, w, pd, row, points)
    }
    /// One value for each of 4 frames (one AVX register).
    type Lanes = [f64; 4];

    #[inline(always)]
    fn lanes(f: impl FnMut(usize) -> f64) -> Lanes {
        std::array::from_fn(f)
    }

    /// Scratch of [`forward_x4`]: per joint, world rotation (`rot[j][col][row]`) and
    /// position (`pos[j][axis]`) of 4 frames at once; sines and cosines per channel.
    pub struct X4 {
        rot: Vec<[[Lanes; 3]; 3]>,
        pos: Vec<[Lanes; 3]>,
        sin: Vec<Lanes>,
        cos: Vec<Lanes>,
    }

    impl X4 {
        pub fn new(skel: &Skeleton, w: &FlatFk) -> X4 {
            let nj = skel.n_joints();
            let nr = w.rot_idx.len();
            X4 {
                rot: vec![[[[0.0; 4]; 3]; 3]; nj],
                pos: vec![[[0.0; 4]; 3]; nj],
                sin: vec![[0.0; 4]; nr],
                cos: vec![[0.0; 4]; nr],
            }
        }
    }

    #[inline(always)]
    fn mul_vec_x4(m: &[[Lanes; 3]; 3], v: &[Lanes; 3]) -> [Lanes; 3] {
        std::array::from_fn(|r| {
            lanes(|l| m[0][r][l] * v[0][l] + m[1][r][l] * v[1][l] + m[2][r][l] * v[2][l])
        })
    }

    #[inline(always)]
    fn rotate_x4(m: &mut [[Lanes; 3]; 3], axis: u8, s: &Lanes, c: &Lanes) {
        #[inline(always)]
        fn mix<const A: usize, const B: usize>(m: &mut [[Lanes; 3]; 3], s: &Lanes, c: &Lanes) {
            let (ca, cb) = (m[A], m[B]);
            m[A] = std::array::from_fn(|r| lanes(|l| c[l] * ca[r][l] + s[l] * cb[r][l]));
            m[B] = std::array::from_fn(|r| lanes(|l| c[l] * cb[r][l] - s[l] * ca[r][l]));
        }
        match axis {
            0 => mix::<1, 2>(m, s, c),
            1 => mix::<2, 0>(m, s, c),
            _ => mix::<0, 1>(m, s, c),
        }
    }

    #[inline(always)]
    fn forward_x4_body(
        skel: &Skeleton,
        w: &FlatFk,
        x: &mut X4,
        rows: [&[f64]; 4],
        points: [&mut [[f64; 3]]; 4],
    ) {
        for (k, &i) in w.rot_idx.iter().enumerate() {
            let a = lanes(|l| rows[l][i]);
            let sc: [(f64, f64); 4] = std::array::from_fn(|l| sincos_deg(a[l]));
            x.sin[k] = lanes(|l| sc[l].0);
            x.cos[k] = lanes(|l| sc[l].1);
        }
        let one = [1.0; 4];
        let zero = [0.0; 4];
        let ident = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
        for j in 0..skel.n_joints() {
            let ch = &skel.channels[j];
            let off = skel.offsets[j];
            let t: [Lanes; 3] = match ch.mode {
                TranslationMode::Offset => off.map(|v| [v; 4]),
                TranslationMode::Replace => std::array::from_fn(|a| match ch.translations[a] {
                    Some(i) => lanes(|l| rows[l][i]),
                    None => [off[a]; 4],
                }),
                TranslationMode::Delta => std::array::from_fn(|a| match ch.translations[a] {
                    Some(i) => lanes(|l| off[a] + rows[l][i]),
                    None => [off[a]; 4],
                }),
            };
            let (mut r, p) = match skel.parents[j] {
                None => (ident, t),
                Some(pj) => {
                    let rp = x.rot[pj];
                    let d = mul_vec_x4(&rp, &t);
                    let pp = x.pos[pj];
                    (rp, std::array::from_fn(|a| lanes(|l| pp[a][l] + d[a][l])))
                }
            };
            let (k0, k1) = w.joint_rot[j];
            for k in k0..k1 {
                rotate_x4(&mut r, w.rot_axis[k], &x.sin[k], &x.cos[k]);
            }
            x.rot[j] = r;
            x.pos[j] = p;
        }
        let nj = skel.n_joints();
        let [p0, p1, p2, p3] = points;
        let mut outs = [p0, p1, p2, p3];
        for j in 0..nj {
            let p = x.pos[j];
            for (l, o) in outs.iter_mut().enumerate() {
                o[j] = [p[0][l], p[1][l], p[2][l]];
            }
        }
        for (e, (j, off)) in skel.end_sites.iter().enumerate() {
            let d = mul_vec_x4(&x.rot[*j], &off.map(|v| [v; 4]));
            let p = x.pos[*j];
            for (l, o) in outs.iter_mut().enumerate() {
                o[nj + e] = [p[0][l] + d[0][l], p[1][l] + d[1][l], p[2][l] + d[2][l]];
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn forward_x4_avx2(
        skel: &Skeleton,
        w: &FlatFk,
        x: &mut X4,
        rows: [&[f64]; 4],
        points: [&mut [[f64; 3]]; 4],
    ) {
        forward_x4_body(skel, w, x, rows, points)
    }

    /// Variant 4: four frames at once, one frame per SIMD lane (AVX2 + FMA when the CPU
    /// has them): every scalar of `fk::forward` becomes 4 lanes, so trig, column mixes
    /// and products all run 4-wide with no shuffles, and the parent-to-child latency is
    /// shared by 4 frames.
    pub fn forward_x4(
        skel: &Skeleton,
        w: &FlatFk,
        x: &mut X4,
        rows: [&[f64]; 4],
        points: [&mut [[f64; 3]]; 4],
    ) {
        assert!(rows.iter().all(|r| r.len() >= skel.n_channels));
        assert!(points.iter().all(|p| p.len() >= skel.n_points()));
        #[cfg(target_arch = "x86_64")]
        if w.avx2 {
            // SAFETY: `avx2` is true only when the CPU reports AVX2 and FMA (`FlatFk::new`).
            return unsafe { forward_x4_avx2(skel, w, x, rows, points) };
        }
        forward_x4_body(skel, w, x, rows, points)
    }
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
