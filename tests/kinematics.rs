//! Kinematic polytopes built with the library (two-pac §3): every kept point lies inside
//! its polytope, the COM sits above the feet, and the tables read back.

use std::collections::BTreeMap;

use stancelib::library::codec::table::Table;
use stancelib::pipeline::commands::twopac::read_polytopes;
use stancelib::pipeline::engine::inputs::discover;
use stancelib::pipeline::engine::streaming::{build_and_write, BuildOptions};

use crate::util::shared_or_skip;

#[test]
fn polytopes_hold_their_points_and_put_the_com_above_the_feet() {
    let Some(data) = shared_or_skip("kinematic polytopes of the shared clips") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    let files = discover(&[data.join("bvh")]).unwrap();
    build_and_write(&files, &lib, &BuildOptions::default(), false).unwrap();
    let polys = read_polytopes(&lib).unwrap();
    let pts = Table::open(&lib.join("kinematics_points.parquet")).unwrap();
    let (ch, eff) = (
        pts.strings("character_id").unwrap(),
        pts.strings("effector").unwrap(),
    );
    let (x, y, z) = (
        pts.f64s("x_m").unwrap(),
        pts.f64s("y_m").unwrap(),
        pts.f64s("z_m").unwrap(),
    );
    assert!(pts.height() > 1000, "{} kinematic points", pts.height());
    let mut per: BTreeMap<(String, String), usize> = BTreeMap::new();
    for i in 0..pts.height() {
        let key = (ch[i].clone(), eff[i].clone());
        *per.entry(key.clone()).or_default() += 1;
        if let Some(p) = polys.get(&key) {
            let v = p.max_violation([x[i], y[i], z[i]]);
            assert!(v <= 1e-9, "{key:?} point {i} outside its polytope by {v} m");
        }
    }
    // Feet: every character with enough foot contacts has a polytope; it holds the mean
    // of its points, the COM is above the foot (z > 0.1 m: the lowest is a fall to the
    // floor) and nowhere near 2.5 m up or below the ground.
    let mut mean: BTreeMap<(String, String), ([f64; 3], f64)> = BTreeMap::new();
    for i in 0..pts.height() {
        let e = mean
            .entry((ch[i].clone(), eff[i].clone()))
            .or_insert(([0.0; 3], f64::INFINITY));
        let n = per[&(ch[i].clone(), eff[i].clone())] as f64;
        e.0 = [e.0[0] + x[i] / n, e.0[1] + y[i] / n, e.0[2] + z[i] / n];
        e.1 = e.1.min(z[i]);
    }
    let mut feet = 0;
    for ((c, e), n) in per
        .iter()
        .filter(|((_, e), n)| e.ends_with("_foot") && **n >= 100)
    {
        let key = (c.clone(), e.clone());
        let p = polys
            .get(&key)
            .unwrap_or_else(|| panic!("{c} {e}: {n} points but no polytope"));
        let (m, z_min) = mean[&key];
        assert!(
            p.contains(m, 1e-9),
            "{c} {e}: the mean point {m:?} is outside"
        );
        assert!(z_min > 0.1, "{c} {e}: COM {z_min} m above the contact");
        assert!(!p.contains([m[0], m[1], 2.5], 0.0) && !p.contains([m[0], m[1], -0.2], 0.0));
        feet += 1;
    }
    assert!(feet >= 10, "{feet} foot polytopes");
    // Sorted as the spec says: (character_id, effector, nx, ny, nz, d).
    let t = Table::open(&lib.join("kinematics.parquet")).unwrap();
    let keys: Vec<(String, String)> = t
        .strings("character_id")
        .unwrap()
        .into_iter()
        .zip(t.strings("effector").unwrap())
        .collect();
    assert!(keys.windows(2).all(|w| w[0] <= w[1]));
}
