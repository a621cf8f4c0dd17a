//! Issue 38 item 5: every picture kind the tool writes, with the command that writes it and
//! a small example in `docs/img/`, as `docs/pictures.md` shows them. The kinds are written
//! as data ([`KINDS`]); the test checks the table against the PNG writers of `src/plot`,
//! runs every command of the page in a demo checkout and checks each picture is written.

use std::path::Path;

use crate::util::{root, Demo};

/// One picture kind: its writer in `src/plot`, the file its command writes (relative to
/// the demo checkout) and its example on the page (relative to `docs/`).
struct Kind {
    writer: &'static str,
    written: &'static str,
    shown: &'static str,
}

/// Every PNG writer of `src/plot` (`pub fn …_png`) with its command's picture.
const KINDS: &[Kind] = &[
    Kind {
        writer: "clip_png",
        written: "out/pictures/clip.png",
        shown: "img/clip.png",
    },
    Kind {
        writer: "stance_png",
        written: "out/pictures/stance.png",
        shown: "img/stance.png",
    },
    Kind {
        writer: "runs_png",
        written: "out/pictures/runs.png",
        shown: "img/runs.png",
    },
    Kind {
        writer: "jump_map_png",
        written: "out/pictures/map/jump_map.png",
        shown: "img/jump_map.png",
    },
    Kind {
        writer: "jump_map_agreement_png",
        written: "out/pictures/map/jump_map_agreement.png",
        shown: "img/jump_map_agreement.png",
    },
    Kind {
        writer: "edit_png",
        written: "out/pictures/edit_run.png",
        shown: "img/edit_run.png",
    },
    Kind {
        writer: "edit_png",
        written: "out/pictures/edit_jump.png",
        shown: "img/edit_jump.png",
    },
    Kind {
        writer: "trajectory_png",
        written: "out/pictures/walk/trajectory.png",
        shown: "img/trajectory.png",
    },
    Kind {
        writer: "trajectory_png",
        written: "out/pictures/walk_issue38/trajectory.png",
        shown: "img/trajectory_invalid.png",
    },
    Kind {
        writer: "equilibrium_png",
        written: "out/pictures/equilibrium.png",
        shown: "img/equilibrium.png",
    },
];

/// Largest example kept in `docs/img/`, bytes (the page should stay light to clone).
const MAX_EXAMPLE_BYTES: u64 = 150 * 1024;

/// The names of the `pub fn …_png(` writers in `src/plot/*.rs` (`write_png` is the
/// atomic-write helper, not a picture).
fn png_writers() -> std::collections::BTreeSet<String> {
    let mut out = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(root().join("src/plot")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        for line in std::fs::read_to_string(&path).unwrap().lines() {
            let Some(rest) = line.trim_start().strip_prefix("pub fn ") else {
                continue;
            };
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if name.ends_with("_png") && name != "write_png" {
                out.insert(name);
            }
        }
    }
    out
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|b| b.starts_with(b"\x89PNG\r\n\x1a\n") && b.len() > 5_000)
}

// See: issue 38 item 5 — "Look at every PNG the tool writes, as a person would, and keep
// one rendered example of each kind in docs/ (small PNGs) so the README can show them."
#[test]
fn issue38_item5_every_picture_kind_is_written_by_its_command() {
    // The table covers every writer of src/plot, so a new kind needs a line here.
    let covered: std::collections::BTreeSet<String> =
        KINDS.iter().map(|k| k.writer.to_string()).collect();
    assert_eq!(covered, png_writers(), "KINDS against src/plot");

    // Every picture the page shows exists, is small, and is one of the kinds.
    let page = std::fs::read_to_string(root().join("docs/pictures.md")).unwrap();
    let shown: Vec<&str> = page
        .split("](")
        .skip(1)
        .filter_map(|s| s.split(')').next())
        .filter(|s| s.ends_with(".png"))
        .collect();
    for kind in KINDS {
        assert!(
            shown.contains(&kind.shown),
            "docs/pictures.md shows no {}",
            kind.shown
        );
    }
    for img in &shown {
        let path = root().join("docs").join(img);
        let len = std::fs::metadata(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .len();
        assert!(is_png(&path), "{} is not a PNG", path.display());
        assert!(len <= MAX_EXAMPLE_BYTES, "{}: {len} bytes", path.display());
    }

    // Every command of the page runs (exit 0) in a demo checkout and writes its picture.
    let demo = Demo::build();
    let mut in_sh = false;
    let mut n = 0;
    for line in page.lines() {
        match line.trim() {
            "```sh" => in_sh = true,
            "```" => in_sh = false,
            cmd if in_sh && cmd.starts_with("stancelib ") => {
                let (code, out, err) = demo.sh(cmd);
                assert_eq!(code, 0, "{cmd}\n{out}{err}");
                n += 1;
            }
            _ => {}
        }
    }
    assert!(n >= 9, "{n} commands on the page");
    for kind in KINDS {
        let path = demo.dir.path().join(kind.written);
        assert!(
            is_png(&path),
            "{} ({}) not written",
            kind.written,
            kind.writer
        );
    }
}

// See: issue 38 (brief item 3) — `query run --help` listed three quantities for a picture
// of four panels; it now names the panels the picture draws.
#[test]
fn issue38_item5_query_run_help_names_the_panels_of_its_picture() {
    let help = crate::util::ok(&["query", "run", "--help"]);
    let n = stancelib::plot::runs::N_PANELS;
    assert_eq!(n, 4);
    assert!(help.contains("four panels"), "{help}");
    for (k, letter) in ["(a)", "(b)", "(c)", "(d)"].iter().enumerate().take(n) {
        assert!(
            help.contains(letter),
            "panel {k} {letter} not named:\n{help}"
        );
    }
    assert!(!help.contains("(e)"), "{help}");
}
