//! `stancelib forces` and `stancelib plot stance` end to end: the export equals the model's
//! evaluation on its grid, integrates to the stored impulse, keeps the force's norm across
//! frames; unknown stances exit 2 and write nothing; the stance plot is a real PNG, with
//! and without the plates of the shared treadmill run.

use crate::util::{fixture_library, ok, s, shared_or_skip, stancelib};
use std::path::{Path, PathBuf};

use stancelib::force_model::export::StanceTimes;
use stancelib::ingest::plates::PlateFoot;
use stancelib::library::codec::table::Table;
use stancelib::library::readers::forces::{read_force_stances, read_up_axis, FORCES_COLUMNS};
use stancelib::pipeline::commands::plots::read_plates;
use stancelib::plot::stance::STANCE_PLOT_PX;
use stancelib::skeleton::units::UpAxis;

fn kv_metadata(path: &Path) -> Vec<(String, String)> {
    let mut f = std::fs::File::open(path).unwrap();
    let meta = polars_parquet::read::read_metadata(&mut f).unwrap();
    meta.key_value_metadata()
        .clone()
        .unwrap_or_default()
        .into_iter()
        .map(|kv| (kv.key, kv.value.unwrap_or_default()))
        .collect()
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

#[test]
fn force_export_is_the_model_on_its_grid_and_integrates_to_the_impulse() {
    let lib = fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.parquet");
    ok(&["forces", "--lib", &s(lib), "--out", &s(&out)]);
    let t = Table::open(&out).unwrap();
    let names: Vec<String> =
        t.df.get_column_names()
            .iter()
            .map(|n| n.to_string())
            .collect();
    assert_eq!(names, FORCES_COLUMNS);
    let ids = t.strings("stance_id").unwrap();
    let col = |n: &str| t.f64s(n).unwrap();
    let (tau, time) = (col("tau"), col("time_clip_s"));
    let f_st = [col("f_h_n"), col("f_p_n"), col("f_v_n")];
    let f_w = [col("fx_n"), col("fy_n"), col("fz_n")];
    // Sorted by stance_id, then tau.
    for i in 1..ids.len() {
        assert!(
            (&ids[i - 1], tau[i - 1]) < (&ids[i], tau[i]),
            "row {i} out of order"
        );
    }
    let kv = kv_metadata(&out);
    let key = |k: &str| kv.iter().find(|(a, _)| a == k).map(|(_, v)| v.clone());
    assert_eq!(
        key("stancelib.tool_version").as_deref(),
        Some(env!("CARGO_PKG_VERSION"))
    );
    assert!(key("stancelib.query").unwrap().contains("\"forces\""));

    let stances_file = lib.join("stances.parquet");
    let stances = read_force_stances(&stances_file).unwrap();
    let st = Table::open(&stances_file).unwrap();
    let (j_v, mass) = (st.f64s("j_v_mps").unwrap(), st.f64s("mass_kg").unwrap());
    assert!(stances.len() >= 10, "{} stances", stances.len());
    let mut start = 0;
    for (k, fs) in stances.iter().enumerate() {
        let m = &fs.stance.model;
        let grid = m.grid();
        let at = ids.iter().position(|i| *i == fs.stance.stance_id).unwrap();
        let rows = at..at + grid.len();
        assert!(rows.clone().all(|r| ids[r] == fs.stance.stance_id));
        assert!(ids.get(rows.end).is_none_or(|i| *i != fs.stance.stance_id));
        start += grid.len();
        let StanceTimes { td_clip_s, dt_s } = fs.times;
        let [hx, hy, _] = fs.heading.e_h;
        for (r, &g) in rows.clone().zip(&grid) {
            assert_eq!(tau[r], g);
            assert_eq!(time[r], td_clip_s + g * dt_s);
            for (a, (col, axis)) in f_st.iter().zip(&m.axes).enumerate() {
                // The export is the model's own evaluation, bit for bit.
                assert_eq!(col[r], axis.eval(g), "{} axis {a}", ids[r]);
            }
            let (fh, fp, fv) = (f_st[0][r], f_st[1][r], f_st[2][r]);
            let w = [f_w[0][r], f_w[1][r], f_w[2][r]];
            assert_eq!(w[2], fv);
            // World = f_h·e_h + f_p·e_p; 1e-12 relative: two products and a sum.
            let scale = 1.0 + fh.abs() + fp.abs();
            assert!((w[0] - (fh * hx - fp * hy)).abs() < 1e-12 * scale);
            assert!((w[1] - (fh * hy + fp * hx)).abs() < 1e-12 * scale);
            // A rotation keeps the norm (|e_h| = 1 to the file's 1e-15).
            let (nw, ns) = (norm(w), norm([fh, fp, fv]));
            assert!((nw - ns).abs() < 1e-12 * (1.0 + ns), "{nw} vs {ns}");
        }
        // Trapezoid rule over the rows' clip times against the stored impulse J_v·m.
        // Error bound: |E| ≤ T·h²/12 · max|f''| (T = Δt, h = Δt/(N_s − 1)); max|f''| is
        // estimated from the rows' second differences, times 2 because the grid can miss
        // the peak of f'' by up to h/2 and a second difference underestimates f'' by
        // sinc²(Ωh/2) (≥ 0.98 at N_s ≥ 16 points per period); plus 1e-9 relative roundoff.
        let fv: Vec<f64> = rows.clone().map(|r| f_st[2][r]).collect();
        let ts: Vec<f64> = rows.clone().map(|r| time[r]).collect();
        let trap: f64 = (1..fv.len())
            .map(|i| 0.5 * (ts[i] - ts[i - 1]) * (fv[i] + fv[i - 1]))
            .sum();
        let h = dt_s / (grid.len() - 1) as f64;
        let f2 = (1..fv.len() - 1)
            .map(|i| (fv[i + 1] - 2.0 * fv[i] + fv[i - 1]).abs() / (h * h))
            .fold(0.0, f64::max);
        let impulse = j_v[k] * mass[k];
        let bound = 2.0 * dt_s * h * h / 12.0 * f2 + 1e-9 * impulse.abs();
        let e = (trap - impulse).abs();
        assert!(
            e <= bound,
            "{}: trapezoid {trap} N·s vs J_v·m {impulse} N·s: error {e:.3e} > bound {bound:.3e}",
            fs.stance.stance_id
        );
        if k == 0 {
            println!(
                "{}: N_s = {}, trapezoid {trap:.6} N·s, J_v·m {impulse:.6} N·s, |error| {e:.2e} ≤ {bound:.2e}",
                fs.stance.stance_id,
                grid.len()
            );
        }
    }
    assert_eq!(start, t.height(), "one row per stance and grid sample");
}

#[test]
fn force_export_of_named_stances_holds_only_those() {
    let lib = fixture_library();
    let stances = read_force_stances(&lib.join("stances.parquet")).unwrap();
    let (a, b) = (
        &stances[stances.len() - 1].stance.stance_id,
        &stances[0].stance.stance_id,
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sub/two.parquet");
    // Given out of order and one twice: each once, sorted by id.
    ok(&[
        "forces",
        "--lib",
        &s(lib),
        "--stance",
        a,
        "--stance",
        b,
        "--stance",
        a,
        "--out",
        &s(&out),
    ]);
    let t = Table::open(&out).unwrap();
    let ids = t.strings("stance_id").unwrap();
    let mut want: Vec<&String> = vec![a, b];
    want.sort();
    let mut seen: Vec<&String> = ids.iter().collect();
    seen.dedup();
    assert_eq!(seen, want);
    let n = |id: &String| {
        let s = stances.iter().find(|s| &s.stance.stance_id == id).unwrap();
        s.stance.model.grid().len()
    };
    assert_eq!(t.height(), n(a) + n(b));
}

#[test]
fn an_unknown_stance_id_exits_2_and_writes_nothing() {
    let lib = fixture_library();
    let dir = tempfile::tempdir().unwrap();
    let good = read_force_stances(&lib.join("stances.parquet")).unwrap()[0]
        .stance
        .stance_id
        .clone();
    let out = dir.path().join("f.parquet");
    let (code, _, err) = stancelib(&[
        "forces",
        "--lib",
        &s(lib),
        "--stance",
        &good,
        "--stance",
        "nosuch:L:7",
        "--out",
        &s(&out),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("nosuch:L:7"), "{err}");
    let png = dir.path().join("p.png");
    let (code, _, err) = stancelib(&[
        "plot",
        "stance",
        "--lib",
        &s(lib),
        "--stance",
        "nosuch:R:3",
        "--out",
        &s(&png),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("nosuch:R:3"), "{err}");
    let (code, _, err) = stancelib(&[
        "plot",
        "stance",
        "--lib",
        &s(lib),
        "--stance",
        &good,
        "--active-set",
        "1.5",
        "--out",
        &s(&png),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--active-set"), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

/// Width and height from a PNG's signature and IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert!(
        b.len() > 10_000,
        "{}: only {} bytes",
        path.display(),
        b.len()
    );
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&b[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
    (be(16), be(20))
}

#[test]
fn plot_stance_writes_a_png_of_the_stated_size() {
    let lib = fixture_library();
    let stances = read_force_stances(&lib.join("stances.parquet")).unwrap();
    let run = stances
        .iter()
        .find(|s| s.stance.clip.starts_with("run_") && s.stance.label == "L")
        .expect("a left-foot running stance in the fixtures");
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("plots/stance.png");
    for extra in [&[][..], &["--active-set", "0.2"][..]] {
        let mut args = vec!["plot", "stance", "--lib"];
        let (l, o) = (s(lib), s(&png));
        args.extend([l.as_str(), "--stance", &run.stance.stance_id, "--out", &o]);
        args.extend(extra);
        ok(&args);
        assert_eq!(png_size(&png), STANCE_PLOT_PX);
    }
    let names: Vec<String> = std::fs::read_dir(png.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["stance.png"], "no temporary file left");
}

/// The shared treadmill run with force plates, built with its subject's mass.
fn hamner_library(data: &Path, dir: &Path) -> PathBuf {
    let clip = data.join("forceplate/hamner_s02_run_4ms/clip.bvh");
    let lib = dir.join("lib");
    ok(&["build", &s(&clip), "--mass", "65.9", "--out", &s(&lib)]);
    lib
}

#[test]
fn plot_stance_with_plates_renders_on_the_treadmill_run() {
    let Some(data) = shared_or_skip("plot_stance_with_plates_renders_on_the_treadmill_run") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let lib = hamner_library(&data, dir.path());
    let grf = data.join("forceplate/hamner_s02_run_4ms/grf.csv");
    let stances = read_force_stances(&lib.join("stances.parquet")).unwrap();
    // A left and a right single-foot stance well inside the recording.
    for label in ["L", "R"] {
        let st = stances
            .iter()
            .find(|s| s.stance.label == label && s.times.td_clip_s > 1.0)
            .unwrap_or_else(|| panic!("no {label} stance after 1 s"));
        // The plate file, mapped with the clip's up axis (+Y), gives that foot's push
        // upwards during the stance: peak between 1.5 and 4 body weights (running).
        let up = read_up_axis(&lib.join("clips.parquet"), &st.stance.clip).unwrap();
        assert_eq!(up, UpAxis::PosY, "the clip's file is +Y up");
        let plates = read_plates(&grf, PlateFoot::from_label(label), up).unwrap();
        let bw = 65.9 * 9.81;
        let peak = plates
            .iter()
            .filter(|p| (st.times.td_clip_s..=st.lo_clip_s).contains(&p.time_s))
            .map(|p| p.f_world[2])
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            (1.5 * bw..4.0 * bw).contains(&peak),
            "{}: plate peak {peak:.0} N = {:.2} BW",
            st.stance.stance_id,
            peak / bw
        );
        let png = dir.path().join(format!("stance_{label}.png"));
        ok(&[
            "plot",
            "stance",
            "--lib",
            &s(&lib),
            "--stance",
            &st.stance.stance_id,
            "--plates",
            &s(&grf),
            "--out",
            &s(&png),
        ]);
        assert_eq!(png_size(&png), STANCE_PLOT_PX);
        println!(
            "{}: plate peak {:.2} BW, model mu_req {:.3} → {}",
            st.stance.stance_id,
            peak / bw,
            st.stance.coef.mu_req,
            png.display()
        );
    }
}
