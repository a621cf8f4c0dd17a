//! The `query jump` answer: every liftoff × landing pair of one character scaled to the
//! requested jump, ranked (spec stance-model §6.9).

use super::feasibility::Limits;
use super::jump::{is_landing, is_liftoff, jump, Jump};
use super::pool::Prepared;
use super::tables::JumpRow;

/// Every same-character (liftoff, landing) pair of `pool` solved for the jump `target`
/// asks of it (apex height above the liftoff contact, distance; m), each side checked
/// against `limits`, ranked: feasible
/// first, then the least change of the recorded forces; ties by stance ids.
pub fn ranked_jump_pairs<'a>(
    pool: &'a [Prepared],
    target: impl Fn(&Prepared, &Prepared) -> (f64, f64),
    limits: impl Fn(&Prepared) -> Limits,
) -> Vec<JumpRow<'a>> {
    let ups: Vec<&Prepared> = pool.iter().filter(|p| is_liftoff(&p.stance)).collect();
    let downs: Vec<&Prepared> = pool.iter().filter(|p| is_landing(&p.stance)).collect();
    let mut rows: Vec<JumpRow> = ups
        .iter()
        .flat_map(|&p1| downs.iter().map(move |&p2| (p1, p2)))
        .filter(|(p1, p2)| p1.stance.character_id == p2.stance.character_id)
        .map(|(p1, p2)| {
            let (height, distance) = target(p1, p2);
            JumpRow {
                liftoff: p1,
                landing: p2,
                height,
                distance,
                limits: [limits(p1), limits(p2)],
                jump: jump(p1, p2, height, distance, Some([limits(p1), limits(p2)]))
                    .map_err(|e| e.to_string()),
            }
        })
        .collect();
    rank(&mut rows);
    rows
}

/// The rank of a solved jump, smallest best: feasible first, then the least change of the
/// recorded forces; a pair without a solution last.
pub fn jump_rank(j: &Result<Jump, String>) -> (bool, f64) {
    match j {
        Ok(j) => (!j.feasible(), j.force_change()),
        Err(_) => (true, f64::INFINITY),
    }
}

/// Feasible first, then the least change of the recorded forces; ties by stance ids.
fn rank(rows: &mut [JumpRow]) {
    rows.sort_by(|x, y| {
        let (kx, ky) = (jump_rank(&x.jump), jump_rank(&y.jump));
        kx.0.cmp(&ky.0).then(kx.1.total_cmp(&ky.1)).then_with(|| {
            (&x.liftoff.stance.stance_id, &x.landing.stance.stance_id)
                .cmp(&(&y.liftoff.stance.stance_id, &y.landing.stance.stance_id))
        })
    });
}
