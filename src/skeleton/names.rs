//! Joint-name normalisation: strip namespaces and shared prefixes, detect the side, and
//! reduce the rest to a lower-case key.
//!
//! # Model
//! ```text
//! "mixamorig:LeftUpLeg" → (L, "upleg")     "Character1_LeftFoot" → (L, "foot")
//! "lfemur" → (L, "femur")                   "Foot_R" → (R, "foot")    "LowerBack" → (–, "lowerback")
//! ```
//!
//! # References
//! spec com-from-bvh §4.1.

/// Body side of a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Side {
    /// Left.
    L,
    /// Right.
    R,
}

/// A normalised joint name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NormName {
    /// The side, when the name carries one.
    pub side: Option<Side>,
    /// Lower-case remainder without `_ - . space`.
    pub key: String,
}

impl NormName {
    /// Helper joints (HumanIK roll/twist, share, MASS `*_RIGMESH`) are never landmarks.
    pub fn is_helper(&self) -> bool {
        ["roll", "twist", "share", "rigmesh"]
            .iter()
            .any(|w| self.key.contains(w))
    }
}

const ASF_BONES: [&str; 12] = [
    "hipjoint", "femur", "tibia", "foot", "toes", "clavicle", "humerus", "radius", "wrist", "hand",
    "fingers", "thumb",
];

fn is_sep(c: char) -> bool {
    matches!(c, '_' | '-' | '.' | ' ')
}

/// Strip a namespace up to the last `:` and a leading `mixamorig<digits>_`.
fn strip_namespace(name: &str) -> &str {
    let n = name.rsplit(':').next().unwrap_or(name);
    if let Some(rest) = n.strip_prefix("mixamorig") {
        let rest = rest.trim_start_matches(|c: char| c.is_ascii_digit());
        if let Some(r) = rest.strip_prefix('_') {
            return r;
        }
    }
    n
}

/// The `<word>_` prefix of a name, if it has one and `word` is not a side token.
fn word_prefix(name: &str) -> Option<&str> {
    let i = name.find('_')?;
    let w = &name[..i];
    let mut cs = w.chars();
    let ok =
        cs.next().is_some_and(|c| c.is_ascii_alphabetic()) && cs.all(|c| c.is_ascii_alphanumeric());
    let side = ["l", "r", "left", "right"].contains(&w.to_ascii_lowercase().as_str());
    (ok && !side).then_some(&name[..=i])
}

/// The shared word prefix (`Character1_`) carried by the root and at least half of all
/// joints, if any (names already namespace-stripped).
pub fn shared_prefix(names: &[&str]) -> Option<String> {
    let root = word_prefix(names.first()?)?;
    let carriers = names.iter().filter(|n| n.starts_with(root)).count();
    (2 * carriers >= names.len()).then(|| root.to_string())
}

/// Split a side prefix/suffix or an ASF side letter off a name.
fn split_side(n: &str) -> (Option<Side>, &str) {
    for (side, words) in [
        (Side::L, ["Left", "left", "LEFT", "L", "l"]),
        (Side::R, ["Right", "right", "RIGHT", "R", "r"]),
    ] {
        for w in words {
            if let Some(rest) = n.strip_prefix(w) {
                match rest.chars().next() {
                    None => return (Some(side), rest),
                    Some(c) if c.is_ascii_uppercase() => return (Some(side), rest),
                    Some(c) if is_sep(c) => return (Some(side), &rest[1..]),
                    _ => {}
                }
            }
        }
    }
    for (side, words) in [
        (Side::L, ["Left", "left", "LEFT", "L", "l"]),
        (Side::R, ["Right", "right", "RIGHT", "R", "r"]),
    ] {
        for w in words {
            if let Some(rest) = n.strip_suffix(w) {
                if rest.len() > 1 && rest.ends_with(is_sep) {
                    return (Some(side), &rest[..rest.len() - 1]);
                }
            }
        }
    }
    let lower = n.to_ascii_lowercase();
    for (side, c) in [(Side::L, 'l'), (Side::R, 'r')] {
        if let Some(rest) = lower.strip_prefix(c) {
            if ASF_BONES.contains(&rest) {
                return (Some(side), &n[1..]);
            }
        }
    }
    (None, n)
}

/// Normalise every joint name of a skeleton (the shared prefix depends on all of them).
pub fn normalise_all(names: &[String]) -> Vec<NormName> {
    let stripped: Vec<&str> = names.iter().map(|n| strip_namespace(n.trim())).collect();
    let prefix = shared_prefix(&stripped);
    stripped
        .iter()
        .map(|n| {
            let n = match &prefix {
                Some(p) => n.strip_prefix(p.as_str()).unwrap_or(n),
                None => n,
            };
            let (side, rest) = split_side(n);
            let key = rest
                .chars()
                .filter(|c| !is_sep(*c))
                .collect::<String>()
                .to_ascii_lowercase();
            NormName { side, key }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(n: &str) -> (Option<Side>, String) {
        // A root without a word prefix, as in every real skeleton (a lone `Foot_L` would
        // carry its own "shared prefix").
        let v = normalise_all(&["Hips".to_string(), n.to_string()]);
        (v[1].side, v[1].key.clone())
    }

    #[test]
    fn sides_and_keys_of_the_shared_conventions() {
        use Side::*;
        let cases = [
            ("LeftUpLeg", Some(L), "upleg"),
            ("RightToeBase", Some(R), "toebase"),
            ("LHipJoint", Some(L), "hipjoint"),
            ("lThigh", Some(L), "thigh"),
            ("rShin", Some(R), "shin"),
            ("L_Foot", Some(L), "foot"),
            ("Foot_L", Some(L), "foot"),
            ("Hand.R", Some(R), "hand"),
            ("foot_left", Some(L), "foot"),
            ("lfemur", Some(L), "femur"),
            ("rtoes", Some(R), "toes"),
            ("lwrist", Some(L), "wrist"),
            ("LowerBack", None, "lowerback"),
            ("Leg", None, "leg"),
            ("lowerneck", None, "lowerneck"),
            ("neckDummy", None, "neckdummy"),
            ("mixamorig:LeftToe_End", Some(L), "toeend"),
            ("mixamorig1_RightHand", Some(R), "hand"),
            ("Head", None, "head"),
            ("LThumb", Some(L), "thumb"),
        ];
        for (n, s, k) in cases {
            assert_eq!(one(n), (s, k.to_string()), "{n}");
        }
    }

    #[test]
    fn shared_word_prefix_is_stripped_and_helpers_flagged() {
        let names: Vec<String> = [
            "Character1_Hips",
            "Character1_LeftUpLeg",
            "L_Talus_RIGMESH",
            "Character1_Head",
        ]
        .map(String::from)
        .to_vec();
        let v = normalise_all(&names);
        assert_eq!(v[0].key, "hips");
        assert_eq!((v[1].side, v[1].key.as_str()), (Some(Side::L), "upleg"));
        assert!(v[2].is_helper());
        assert_eq!(v[3].key, "head");
    }
}
