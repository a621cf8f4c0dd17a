//! Issue 11, filesystem and output safety: `--out` never destroys what the tool did not
//! write (inputs, foreign folders, files); input folder links and cycles; special files
//! and the size bound; one per-input error rule for explicit and walked inputs; stale
//! temporaries of killed runs; the advisory lock of a build.

use std::path::{Path, PathBuf};

use stancelib::library::codec::table::read_parquet;

use super::cli::{fixture, good_fixtures, stancelib, strings, tmp};

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// A folder `dir` holding copies of the first `n` good fixtures; their paths.
fn clips_in(dir: &Path, n: usize) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).unwrap();
    good_fixtures()
        .iter()
        .take(n)
        .map(|f| {
            let to = dir.join(Path::new(f).file_name().unwrap());
            std::fs::copy(f, &to).unwrap();
            to
        })
        .collect()
}

/// Every file under `dir` (not following links) with its bytes, sorted.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = std::fs::symlink_metadata(&p).unwrap();
            if m.is_dir() {
                stack.push(p);
            } else if m.is_file() {
                let bytes = std::fs::read(&p).unwrap();
                out.push((p, bytes));
            }
        }
    }
    out.sort();
    out
}

/// `build <inputs> --out <out> <extra>`.
fn build(inputs: &[&Path], out: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args: Vec<String> = vec!["build".into()];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    args.extend(extra.iter().map(|e| e.to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    stancelib(&args)
}

/// `frames <inputs> --out <out>`.
fn frames(inputs: &[&Path], out: &Path) -> (i32, String, String) {
    let mut args: Vec<String> = vec!["frames".into()];
    args.extend(inputs.iter().map(|p| s(p)));
    args.extend(["--out".into(), s(out)]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    stancelib(&args)
}

/// (clip, status, message) of `clips.parquet` in `dir`.
fn clip_rows(dir: &Path) -> Vec<(String, String, String)> {
    let clips = read_parquet(&dir.join("clips.parquet")).unwrap();
    let msg: Vec<String> = clips
        .column("message")
        .unwrap()
        .str()
        .unwrap()
        .iter()
        .map(|m| m.unwrap_or_default().to_string())
        .collect();
    strings(&clips, "clip")
        .into_iter()
        .zip(strings(&clips, "status"))
        .zip(msg)
        .map(|((c, st), m)| (c, st, m))
        .collect()
}

/// A process id that is certainly not running: a child that has been waited for.
#[cfg(unix)]
fn dead_pid() -> u32 {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

// See: issue 11 item 1 — `build clips/ --out clips/` deleted the input clips.
#[test]
fn out_naming_the_input_folder_is_refused_and_the_clips_survive() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 2);
    let before = snapshot(&clips);
    for extra in [&[][..], &["--force"][..]] {
        let (code, _, err) = build(&[&clips], &clips, extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("is the input"), "{err}");
        assert_eq!(snapshot(&clips), before, "{extra:?}: the inputs changed");
    }
    let leftovers: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

// See: issue 11 item 1 — `--out` a parent folder of the inputs wiped it.
#[test]
fn out_containing_or_inside_an_input_is_refused_even_with_force() {
    let d = tmp();
    let data = d.path().join("data");
    let files = clips_in(&data.join("clips"), 1);
    let before = snapshot(d.path());
    // A parent of the input folder, and a parent of an input file given explicitly.
    let (code, _, err) = build(&[&data.join("clips")], &data, &["--force"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("contains the input"), "{err}");
    let (code, _, err) = build(&[&files[0]], &data, &["--force"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("contains the input"), "{err}");
    // Inside an input folder, not existing yet (its nearest existing ancestor decides),
    // and reached through `..`.
    let inside = data.join("clips/new/lib");
    let (code, _, err) = build(&[&data.join("clips")], &inside, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("lies inside the input"), "{err}");
    let dotted = data.join("other/../clips/lib");
    let (code, _, err) = build(&[&data.join("clips")], &dotted, &[]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(
        snapshot(d.path()),
        before,
        "a refused build changed the folder"
    );
    assert!(!data.join("clips/new").exists());
}

// See: issue 11 item 1 — a pipeline `out` naming its own input folder deleted the clips.
#[test]
fn a_pipeline_out_naming_its_input_folder_is_refused() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 1);
    let before = snapshot(&clips);
    let job = d.path().join("job.toml");
    std::fs::write(&job, "inputs = [\"clips/*.bvh\"]\nout = \"clips\"\n").unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let mut args = vec!["run", job.to_str().unwrap()];
        args.extend(extra);
        let (code, _, err) = stancelib(&args);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("contains the input"), "{err}");
        assert_eq!(snapshot(&clips), before, "{extra:?}: the inputs changed");
    }
}

// See: issue 11 item 1 — any existing folder that is not a library was emptied.
#[test]
fn out_naming_a_folder_that_is_not_a_library_is_refused_unless_forced() {
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let notes = d.path().join("notes");
    std::fs::create_dir_all(notes.join("sub")).unwrap();
    std::fs::write(notes.join("todo.txt"), "keep me").unwrap();
    std::fs::write(notes.join("sub/manifest.json"), "{}").unwrap();
    // A manifest.json that is not a library's does not make the folder one.
    std::fs::write(notes.join("manifest.json"), r#"{"name": "my-app"}"#).unwrap();
    let before = snapshot(&notes);
    let (code, _, err) = build(&[&clip], &notes, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not a stancelib library") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(snapshot(&notes), before);
    let (code, _, err) = build(&[&clip], &notes, &["--force"]);
    assert_eq!(code, 0, "{err}");
    assert!(!notes.join("todo.txt").exists());
    assert!(notes.join("stances.parquet").is_file());
}

// See: issue 11 item 2 — a regular file as `--out` was replaced by a library folder.
#[test]
fn out_naming_a_regular_file_is_refused_and_the_file_is_intact() {
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let file = d.path().join("results.bin");
    let bytes: Vec<u8> = (0..=255u8).cycle().take(10_000).collect();
    std::fs::write(&file, &bytes).unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let (code, _, err) = build(&[&clip], &file, extra);
        assert_eq!(code, 2, "{extra:?}: {err}");
        assert!(err.contains("is a regular file, not a folder"), "{err}");
        assert_eq!(std::fs::read(&file).unwrap(), bytes);
    }
    let (code, _, err) = frames(&[&clip], &file);
    assert_eq!(code, 2, "{err}");
    assert_eq!(std::fs::read(&file).unwrap(), bytes);
    let names: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "no hidden temporary is left: {names:?}");
}

// See: issue 11 item 1 — `frames --out DIR` writes into DIR by temporary and rename: it
// replaces only its own tables, so the inputs in DIR survive.
#[test]
fn frames_into_its_input_folder_replaces_only_its_own_tables() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 2);
    std::fs::write(clips.join("notes.txt"), "keep me").unwrap();
    let before = snapshot(&clips);
    let (code, _, err) = frames(&[&clips], &clips);
    assert_eq!(code, 0, "{err}");
    let after = snapshot(&clips);
    for (p, bytes) in &before {
        assert!(
            after.contains(&(p.clone(), bytes.clone())),
            "{} changed",
            p.display()
        );
    }
    let added: Vec<String> = after
        .iter()
        .filter(|f| !before.contains(f))
        .map(|(p, _)| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        added,
        vec!["clips.parquet", "contacts.parquet", "frames.parquet"]
    );
}

// See: issue 11 item 12 — I/O errors dropped the OS reason.
#[test]
fn an_unwritable_out_names_the_os_reason() {
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let file = d.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let (code, _, err) = build(&[&clip], &file.join("lib"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a-file") && err.contains("os error"), "{err}");
}

// See: issue 11 item 1 — what may be replaced: a library (new and older manifests) and an
// empty folder.
#[test]
fn an_existing_library_or_empty_folder_is_replaced() {
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let lib = d.path().join("lib");
    std::fs::create_dir(&lib).unwrap();
    assert_eq!(build(&[&clip], &lib, &[]).0, 0, "an empty folder");
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(lib.join("manifest.json")).unwrap()).unwrap();
    let schema = format!(
        "stancelib.library/{}",
        stancelib::library::codec::schema::SCHEMA_VERSION
    );
    assert_eq!(manifest["schema"], schema.as_str());
    let (code, _, err) = build(&[&clip], &lib, &[]);
    assert_eq!(code, 0, "a library: {err}");
    // A library written before the `schema` key.
    let mut old = manifest.clone();
    old.as_object_mut().unwrap().remove("schema");
    std::fs::write(lib.join("manifest.json"), old.to_string()).unwrap();
    std::fs::write(lib.join("stale.txt"), "from an old build").unwrap();
    let (code, _, err) = build(&[&clip], &lib, &[]);
    assert_eq!(code, 0, "an older library: {err}");
    assert!(!lib.join("stale.txt").exists());
    let leftovers: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

// See: issue 11 item 4 — one directory self-link ingested the same clip 41 times.
#[cfg(unix)]
#[test]
fn a_self_linked_input_folder_gives_each_clip_once() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 2);
    std::os::unix::fs::symlink(".", clips.join("again")).unwrap();
    let out = d.path().join("out");
    let (code, _, err) = frames(&[&clips], &out);
    assert_eq!(code, 0, "{err}");
    let rows = clip_rows(&out);
    assert_eq!(rows.len(), 2, "{rows:?}");
    assert!(rows.iter().all(|r| r.1 == "ok"), "{rows:?}");
}

// See: issue 11 item 4 — two directory links pointing at each other never finished.
#[cfg(unix)]
#[test]
fn a_two_link_cycle_terminates_with_each_clip_once() {
    let d = tmp();
    let (a, b) = (d.path().join("a"), d.path().join("b"));
    let fa = clips_in(&a, 1);
    std::fs::create_dir_all(&b).unwrap();
    let fb = b.join("other.bvh");
    std::fs::copy(fixture("jump_100hz_m_zup.bvh"), &fb).unwrap();
    std::os::unix::fs::symlink("../b", a.join("to_b")).unwrap();
    std::os::unix::fs::symlink("../a", b.join("to_a")).unwrap();
    let out = d.path().join("out");
    // Both folders, and a file of each given again: still each file once.
    let (code, _, err) = frames(&[&a, &b, &fa[0], &fb], &out);
    assert_eq!(code, 0, "{err}");
    let rows = clip_rows(&out);
    assert_eq!(rows.len(), 2, "{rows:?}");
}

// See: issue 11 item 5 — a FIFO named `*.bvh` hung the batch, a link to /dev/zero grew
// memory until the batch aborted.
#[cfg(unix)]
#[test]
fn a_fifo_or_device_named_bvh_is_a_per_input_error() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 1);
    let fifo = clips.join("x.bvh");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    std::os::unix::fs::symlink("/dev/zero", clips.join("zero.bvh")).unwrap();
    let lib = d.path().join("lib");
    let (code, _, err) = build(&[&clips], &lib, &[]);
    assert_eq!(code, 1, "{err}");
    let errors = read_parquet(&lib.join("errors.parquet")).unwrap();
    let (stage, msg) = (strings(&errors, "stage"), strings(&errors, "message"));
    assert_eq!(stage, vec!["input", "input"], "{msg:?}");
    assert!(
        msg.iter()
            .any(|m| m.contains("x.bvh") && m.contains("FIFO")),
        "{msg:?}"
    );
    assert!(
        msg.iter()
            .any(|m| m.contains("zero.bvh") && m.contains("symbolic link to a character device")),
        "{msg:?}"
    );
    let rows = clip_rows(&lib);
    assert_eq!(rows.iter().filter(|r| r.1 == "ok").count(), 1, "{rows:?}");
}

// See: issue 11 item 5 — a size bound on input files, checked before reading.
#[test]
fn a_file_over_the_size_limit_is_a_per_input_error() {
    let d = tmp();
    let clips = d.path().join("clips");
    clips_in(&clips, 1);
    // Sparse: no disk space, no read (the size is refused before the file is opened).
    let big = std::fs::File::create(clips.join("huge.bvh")).unwrap();
    big.set_len(stancelib::pipeline::engine::inputs::MAX_BVH_BYTES + 1)
        .unwrap();
    let out = d.path().join("out");
    let (code, _, err) = frames(&[&clips], &out);
    assert_eq!(code, 1, "{err}");
    let rows = clip_rows(&out);
    let huge = rows
        .iter()
        .find(|r| r.0 == "huge")
        .expect("a row for huge.bvh");
    assert_eq!(huge.1, "error");
    assert!(huge.2.contains("MAX_BVH_BYTES"), "{}", huge.2);
}

// See: issue 11 item 9 — one bad explicit input aborted the batch (exit 2, nothing
// written, "no such file or folder").
#[cfg(unix)]
#[test]
fn a_dangling_link_given_explicitly_is_a_per_input_error() {
    let d = tmp();
    let good = clips_in(&d.path().join("clips"), 1);
    let dangling = d.path().join("gone.bvh");
    std::os::unix::fs::symlink(d.path().join("nowhere.bvh"), &dangling).unwrap();
    let missing = d.path().join("missing.bvh");
    let lib = d.path().join("lib");
    let (code, _, err) = build(&[&good[0], &dangling, &missing], &lib, &[]);
    assert_eq!(code, 1, "{err}");
    let errors = read_parquet(&lib.join("errors.parquet")).unwrap();
    let (stage, msg) = (strings(&errors, "stage"), strings(&errors, "message"));
    assert_eq!(stage, vec!["input", "input"], "{msg:?}");
    let of = |name: &str| {
        msg.iter()
            .find(|m| m.contains(name))
            .cloned()
            .unwrap_or_default()
    };
    assert!(of("gone.bvh").contains("dangling symbolic link"), "{msg:?}");
    assert!(of("gone.bvh").contains("os error"), "{msg:?}");
    assert!(of("missing.bvh").contains("not found"), "{msg:?}");
    let rows = clip_rows(&lib);
    assert_eq!(rows.iter().filter(|r| r.1 == "ok").count(), 1, "{rows:?}");
    // When no input at all can be read, nothing is written (exit 2).
    let lib2 = d.path().join("lib2");
    let (code, _, err) = build(&[&dangling], &lib2, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("dangling symbolic link"), "{err}");
    assert!(!lib2.exists());
}

// See: issue 11 item 12 — temporary folders of killed runs were never removed.
#[cfg(unix)]
#[test]
fn stale_temporaries_of_dead_processes_are_removed_and_live_ones_kept() {
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let (dead, live) = (dead_pid(), std::process::id());
    let keep = [
        format!(".lib.tmp-{live}"),
        format!(".other.tmp-{dead}"),
        format!(".lib.tmp-{dead}.mine"),
        format!("lib.tmp-{dead}"),
    ];
    let gone = format!(".lib.tmp-{dead}");
    for n in keep.iter().chain([&gone]) {
        std::fs::create_dir_all(d.path().join(n).join("frames.parquet")).unwrap();
    }
    let (code, _, err) = build(&[&clip], &d.path().join("lib"), &[]);
    assert_eq!(code, 0, "{err}");
    assert!(!d.path().join(&gone).exists(), "{gone} was not removed");
    for n in &keep {
        assert!(
            d.path().join(n).join("frames.parquet").exists(),
            "{n} was removed"
        );
    }
    // frames: the temporary tables of a dead run in DIR go, anything else stays.
    let out = d.path().join("tables");
    std::fs::create_dir_all(&out).unwrap();
    let (stale, mine, other) = (
        format!(".frames.parquet.tmp-{dead}"),
        format!(".frames.parquet.tmp-{live}"),
        "frames.parquet.bak".to_string(),
    );
    for n in [&stale, &mine, &other] {
        std::fs::write(out.join(n), "x").unwrap();
    }
    assert_eq!(frames(&[&clip], &out).0, 0);
    assert!(!out.join(&stale).exists());
    assert!(out.join(&mine).exists() && out.join(&other).exists());
}

// See: issue 11 item 13 — racing builds into one `--out`: the last to finish won silently.
#[cfg(target_os = "linux")]
#[test]
fn a_held_lock_makes_a_second_build_exit_2() {
    use std::io::Write;
    use std::os::unix::io::AsRawFd;
    let d = tmp();
    let clip = PathBuf::from(fixture("run_30hz_in_yup.bvh"));
    let lib = d.path().join("lib");
    assert_eq!(build(&[&clip], &lib, &[]).0, 0);
    let before = snapshot(&lib);
    let lock_path = d.path().join(".lib.lock");
    let mut lock = std::fs::File::create(&lock_path).unwrap();
    write!(lock, "{}", std::process::id()).unwrap();
    // SAFETY: a valid open descriptor.
    assert_eq!(
        unsafe { libc::flock(lock.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) },
        0
    );
    let (code, _, err) = build(&[&clip], &lib, &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(".lib.lock"), "{err}");
    assert!(
        err.contains(&format!("process {}", std::process::id())),
        "{err}"
    );
    assert_eq!(snapshot(&lib), before, "the locked library changed");
    // Released (as at the holder's death), the file left behind does not block.
    drop(lock);
    let (code, _, err) = build(&[&clip], &lib, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(
        !lock_path.exists(),
        "the lock file is removed at the end of a build"
    );
}

// See: the review of issue 39 item 3 — `forces --per-contact --clip C --out
// L/frames.parquet` exited 0 and the next read of L failed ("column 'ground_z_m':
// missing"); `forces --out L/stances.parquet` broke `info`. An output that is one of the
// library's own files (its tables, its manifest, a dataset table's folder, the folder
// itself) is refused before any work, and the library is byte-for-byte what it was; an
// output beside the tables (the pipelines' `runs.parquet`) is still written.
#[test]
fn outputs_refuse_to_replace_the_librarys_own_files() {
    use super::util::{ok, refused};
    let dir = tmp();
    let lib = dir.path().join("lib");
    let clip = fixture("run_120hz_m_yup.bvh");
    ok(&["build", &clip, "--out", &s(&lib), "--quiet"]);
    let before = snapshot(&lib);
    let (l, o) = (s(&lib), |name: &str| s(&lib.join(name)));
    let stance = "run_120hz_m_yup:R:51";
    for args in [
        vec![
            "forces",
            "--lib",
            &l,
            "--per-contact",
            "--clip",
            "run_120hz_m_yup",
            "--out",
            &o("frames.parquet"),
        ],
        vec!["forces", "--lib", &l, "--out", &o("stances.parquet")],
        vec![
            "query",
            "run",
            "--lib",
            &l,
            "--speed",
            "3",
            "--out",
            &o("clips.parquet"),
        ],
        vec![
            "query",
            "jump",
            "--lib",
            &l,
            "--height",
            "1.3",
            "--out",
            &o("manifest.json"),
        ],
        vec![
            "plot",
            "stance",
            "--lib",
            &l,
            "--stance",
            stance,
            "--out",
            &o("contacts.parquet"),
        ],
        vec!["edit", "run", "--lib", &l, "--speed", "3", "--out", &l],
        vec!["forces", "--lib", &l, "--out", &o("stances/part.parquet")],
    ] {
        refused(&args, &["--out", "library"]);
    }
    assert_eq!(snapshot(&lib), before, "the library changed");
    ok(&["info", &l]);
    ok(&[
        "query",
        "run",
        "--lib",
        &l,
        "--speed",
        "3",
        "--out",
        &o("runs.parquet"),
        "--quiet",
    ]);
}
