//! Stance ids (`<clip>:<label>:<frame>`, written by [`super::assemble`]) and the ids nearest to
//! one a library does not hold, for the suggestion of an error message.
//!
//! # Model
//! ```text
//! id = clip ":" label ":" frame      (the clip name may itself hold ':'; label and frame
//!                                     are the last two fields)
//! distance(a, b) = (clip differs, label differs, |frame_a − frame_b|)   compared in order;
//!                  an id without a frame number sorts after every one with it
//! ```
//! `09_01:R:41` thus suggests `09_01:R:40` before `09_01:L:41` and before any stance of
//! another clip.
//!
//! # Examples
//! ```
//! use stancelib::stances::ids::nearest_ids;
//! let held = ["01_01:LR:150", "09_01:L:41", "09_01:R:40", "09_01:R:90"];
//! assert_eq!(nearest_ids("09_01:R:41", held.iter().copied(), 2), ["09_01:R:40", "09_01:R:90"]);
//! ```

/// The `(clip, label, frame)` of a stance id; `None` when it has fewer than three fields.
pub fn parse(id: &str) -> Option<(&str, &str, Option<i64>)> {
    let mut it = id.rsplitn(3, ':');
    let frame = it.next()?;
    let label = it.next()?;
    let clip = it.next()?;
    Some((clip, label, frame.parse().ok()))
}

/// How far a held id is from the one asked: (another clip, another label, frames apart,
/// the id itself for ties), compared in that order.
type Distance = (bool, bool, u64, String);

/// Up to `n` ids of `held` nearest to `id` (see the module docs), nearest first; ties by id.
pub fn nearest_ids<'a>(id: &str, held: impl Iterator<Item = &'a str>, n: usize) -> Vec<&'a str> {
    let want = parse(id);
    let key = |h: &str| -> Distance {
        match (want, parse(h)) {
            (Some((c, l, f)), Some((hc, hl, hf))) => (
                c != hc,
                l != hl,
                match (f, hf) {
                    (Some(a), Some(b)) => a.abs_diff(b),
                    _ => u64::MAX,
                },
                h.to_string(),
            ),
            _ => (true, true, u64::MAX, h.to_string()),
        }
    };
    let mut all: Vec<(Distance, &str)> = held.map(|h| (key(h), h)).collect();
    all.sort();
    all.into_iter().take(n).map(|(_, h)| h).collect()
}

/// `no stance 'ID' in this library (N stances); nearest: A, B, C`.
pub fn unknown_stance_message<'a>(id: &str, held: impl Iterator<Item = &'a str> + Clone) -> String {
    let n = held.clone().count();
    let near = nearest_ids(id, held, 3);
    if near.is_empty() {
        format!("no stance '{id}' in this library (it holds no stances)")
    } else {
        format!(
            "no stance '{id}' in this library ({n} stances); nearest: {}",
            near.join(", ")
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clip_name_with_colons_keeps_its_label_and_frame() {
        assert_eq!(parse("a:b:L:12"), Some(("a:b", "L", Some(12))));
        assert_eq!(parse("x:LR:y"), Some(("x", "LR", None)));
        assert_eq!(parse("nocolon"), None);
    }

    #[test]
    fn the_same_clip_and_foot_come_first_then_the_nearest_frame() {
        let held = ["b:R:41", "a:L:41", "a:R:10", "a:R:45", "zz"];
        assert_eq!(
            nearest_ids("a:R:41", held.iter().copied(), 4),
            ["a:R:45", "a:R:10", "a:L:41", "b:R:41"]
        );
        let msg = unknown_stance_message("a:R:41", held.iter().copied());
        assert!(
            msg.contains("(5 stances); nearest: a:R:45, a:R:10, a:L:41"),
            "{msg}"
        );
    }
}
