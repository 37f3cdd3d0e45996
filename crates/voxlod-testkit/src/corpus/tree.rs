//! A plant of thin tubes: a trunk, branches and twigs, each a closed tube (its own shell) that
//! starts on its parent's centre line, inside the parent, so the shells overlap where they
//! join. Curves bend upwards; radii taper along each tube.

use glam::DVec3;

use voxlod_core::TriangleMesh;

use super::build::{joined, tube, Rng};

/// Children of a tube of each level (the last level has none).
const CHILDREN: [usize; 3] = [6, 4, 2];

/// Tubes in the plant: 1 + 6 + 6·4 + 6·4·2.
pub(super) const TUBES: usize = 79;

/// One tube to grow: where it starts, which way, how long and how thick at its base.
#[derive(Clone, Copy)]
struct Shoot {
    start: DVec3,
    direction: DVec3,
    length: f64,
    radius: f64,
    level: usize,
}

/// The plant: a trunk of height about 1 and base radius `trunk_radius`; [`TUBES`] closed tubes.
pub(super) fn plant(trunk_radius: f64) -> TriangleMesh {
    let mut rng = Rng::new(0x7EE5);
    let mut tubes = Vec::with_capacity(TUBES);
    let mut pending = vec![Shoot {
        start: DVec3::ZERO,
        direction: DVec3::Z,
        length: 1.0,
        radius: trunk_radius,
        level: 0,
    }];
    while let Some(shoot) = pending.pop() {
        let (points, sides) = if shoot.level == 0 { (40, 12) } else { (16, 8) };
        let centre = curve(&shoot, points);
        let taper = |k: usize| shoot.radius * (1.0 - 0.2 * k as f64 / (points - 1) as f64);
        tubes.push(tube(&centre, sides, taper));
        let Some(&children) = CHILDREN.get(shoot.level) else {
            continue;
        };
        for c in 0..children {
            let k = ((points - 1) as f64 * rng.range(0.35, 0.9)) as usize;
            let around = std::f64::consts::TAU * (c as f64 + rng.range(0.0, 0.6)) / children as f64;
            pending.push(Shoot {
                start: centre[k],
                direction: sideways(&centre, k, around, rng.range(0.6, 1.0)),
                length: shoot.length * 0.55,
                radius: taper(k) * 0.8,
                level: shoot.level + 1,
            });
        }
    }
    joined(tubes)
}

/// The centre line of `shoot`: `points` points along its direction, bending upwards.
fn curve(shoot: &Shoot, points: usize) -> Vec<DVec3> {
    let up = DVec3::Z - shoot.direction * shoot.direction.dot(DVec3::Z);
    (0..points)
        .map(|k| {
            let s = k as f64 / (points - 1) as f64;
            shoot.start + shoot.length * (shoot.direction * s + 0.25 * up * s * s)
        })
        .collect()
}

/// A direction leaving the curve `centre` at point k, `angle` radians off its direction, turned
/// `around` radians about it.
fn sideways(centre: &[DVec3], k: usize, around: f64, angle: f64) -> DVec3 {
    let ahead = (centre[(k + 1).min(centre.len() - 1)] - centre[k.saturating_sub(1)]).normalize();
    let across = glam::DQuat::from_axis_angle(ahead, around) * ahead.any_orthonormal_vector();
    (ahead * angle.cos() + across * angle.sin()).normalize()
}
