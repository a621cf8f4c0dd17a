//! Issue 38 item 4 — a body mass per clip or subject from a table (`--masses FILE`,
//! pipeline `masses`), recorded in `clips.parquet` (`mass_kg`, `mass_source`) and `info`;
//! the default mass is a warning.

use stancelib::library::codec::table::Table;

use crate::util::{ok, s, stancelib};

/// The same run under two names (two "subjects") and a third clip no row names.
fn inputs(dir: &std::path::Path) -> std::path::PathBuf {
    let inputs = dir.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bvh");
    for (src, dst) in [
        ("run_120hz_m_yup.bvh", "s01_run.bvh"),
        ("run_120hz_m_yup.bvh", "s02_run.bvh"),
        ("run_60hz_cm_zup.bvh", "other.bvh"),
    ] {
        std::fs::copy(fixtures.join(src), inputs.join(dst)).unwrap();
    }
    inputs
}

/// Per clip of a library: (mass_kg, mass_source, largest stance f_peak_n).
fn clip_masses(lib: &std::path::Path) -> std::collections::BTreeMap<String, (f64, String, f64)> {
    let c = Table::open(&lib.join("clips.parquet")).unwrap();
    let st = Table::open(&lib.join("stances.parquet")).unwrap();
    let (sc, peak) = (st.strings("clip").unwrap(), st.f64s("f_peak_n").unwrap());
    let (names, mass, source) = (
        c.strings("clip").unwrap(),
        c.f64s("mass_kg").unwrap(),
        c.strings("mass_source").unwrap(),
    );
    names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            let p = sc
                .iter()
                .zip(&peak)
                .filter(|(c, _)| *c == n)
                .map(|(_, p)| *p)
                .fold(0.0, f64::max);
            (n.clone(), (mass[i], source[i].clone(), p))
        })
        .collect()
}

// See: issue 38 item 4 — one mass for a whole build, 70 kg unless --mass, never flagged.
#[test]
fn a_masses_table_gives_each_clip_its_mass_and_the_default_is_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = inputs(dir.path());
    let table = dir.path().join("masses.csv");
    // Specific row first: s01_run is 90 kg, every other s0* clip 60 kg.
    std::fs::write(&table, "clip,mass_kg,sex\ns01_run,90,female\ns0?_*,60\n").unwrap();
    let lib = dir.path().join("lib");
    let (code, _, err) = stancelib(&[
        "build",
        &s(&inputs),
        "--out",
        &s(&lib),
        "--masses",
        &s(&table),
    ]);
    assert_eq!(code, 0, "{err}");
    let m = clip_masses(&lib);
    let t = table.display().to_string();
    assert_eq!(
        (m["s01_run"].0, m["s01_run"].1.as_str()),
        (90.0, format!("table {t}:2").as_str())
    );
    assert_eq!(
        (m["s02_run"].0, m["s02_run"].1.as_str()),
        (60.0, format!("table {t}:3").as_str())
    );
    assert_eq!((m["other"].0, m["other"].1.as_str()), (70.0, "default"));
    // The same recording under two masses: its forces in newtons scale with the mass
    // (the female de Leva column moves the COM a little, so the run's force shape is
    // compared with a tolerance of a few per cent, not to round-off).
    let ratio = m["s01_run"].2 / m["s02_run"].2;
    eprintln!("f_peak 90 kg / 60 kg: {ratio:.4} (mass ratio 1.5)");
    assert!((ratio / 1.5 - 1.0).abs() < 0.05, "{ratio}");
    // The default is a warning: on the clip's row and in info.
    let c = Table::open(&lib.join("clips.parquet")).unwrap();
    let names = c.strings("clip").unwrap();
    let warnings = c.df.column("warnings").unwrap().list().unwrap().clone();
    for (i, n) in names.iter().enumerate() {
        let w = warnings.get_as_series(i).expect("a warnings list");
        let flagged = w
            .str()
            .unwrap()
            .iter()
            .flatten()
            .any(|x| x.contains("body mass 70 kg assumed"));
        assert_eq!(flagged, n == "other", "{n}");
    }
    let info = ok(&["info", &s(&lib)]);
    assert!(
        info.contains("masses (clips)") && info.contains("default 1, table 2"),
        "{info}"
    );
    assert!(info.contains("were given 70 kg"), "{info}");
    // --mass given: no default, no warning.
    let lib2 = dir.path().join("lib2");
    ok(&[
        "build",
        &s(&inputs),
        "--out",
        &s(&lib2),
        "--mass",
        "75",
        "--quiet",
    ]);
    let m2 = clip_masses(&lib2);
    assert!(
        m2.values()
            .all(|(kg, src, _)| *kg == 75.0 && src == "mass_kg"),
        "{m2:?}"
    );
}

// See: issue 38 item 4 — the pipeline key, relative to the pipeline file.
#[test]
fn a_pipeline_names_its_masses_table() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = inputs(dir.path());
    std::fs::write(dir.path().join("m.csv"), "clip,mass_kg\n*,82.5\n").unwrap();
    let pipe = dir.path().join("job.toml");
    std::fs::write(
        &pipe,
        format!(
            "inputs = [\"{}\"]\nout = \"lib\"\nmasses = \"m.csv\"\n",
            s(&inputs)
        ),
    )
    .unwrap();
    ok(&["run", &s(&pipe), "--quiet"]);
    let m = clip_masses(&dir.path().join("lib"));
    assert!(
        m.values()
            .all(|(kg, src, _)| *kg == 82.5 && src.ends_with("m.csv:2")),
        "{m:?}"
    );
}

// See: issue 38 item 4 and issue 40 item 5 — a bad table or mass is refused before any work.
#[test]
fn bad_masses_are_refused_naming_file_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = inputs(dir.path());
    let lib = dir.path().join("lib");
    for (text, want) in [
        ("clip,kg\na,70\n", "clip and mass_kg"),
        (
            "clip,mass_kg\ns01_run,heavy\n",
            ":2: mass_kg 'heavy' is not a number",
        ),
        ("clip,mass_kg\ns01_run,1e300\n", "[1, 1000] kg"),
    ] {
        let table = dir.path().join("bad.csv");
        std::fs::write(&table, text).unwrap();
        let (code, _, err) = stancelib(&[
            "build",
            &s(&inputs),
            "--out",
            &s(&lib),
            "--masses",
            &s(&table),
        ]);
        assert_eq!(code, 2, "{text:?}: {err}");
        assert!(
            err.contains("bad.csv") && err.contains(want),
            "{text:?}: {err}"
        );
        assert!(!lib.exists(), "nothing written for {text:?}");
    }
    let (code, _, err) = stancelib(&["build", &s(&inputs), "--out", &s(&lib), "--mass", "1e300"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--mass") && err.contains("[1, 1000] kg"),
        "{err}"
    );
}
