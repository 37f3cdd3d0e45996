//! The mesh while [`super::clean_mesh`] edits it: the surface itself (positions in `f64`,
//! triangles with a live flag), each vertex's triangles ([`Fans`]) and the crossing guard's
//! buckets, with the queries the cleaning steps ask of them.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use voxlod_core::crossings::triangles_meet;
use voxlod_core::TriangleMesh;

use super::changes::Changes;
use super::fans::Fans;
use crate::local_crossings::Buckets;

/// The surface being cleaned: what is left of the mesh once cleaning's helpers are dropped.
pub(super) struct Surface {
    pub(super) positions: Vec<DVec3>,
    pub(super) normals: Vec<Vec3>,
    pub(super) triangles: Vec<[u32; 3]>,
    pub(super) alive: Vec<bool>,
}

/// The surface with each vertex's triangles, the vertices moved in this pass, and the guard's
/// buckets.
pub(super) struct Work {
    pub(super) surface: Surface,
    pub(super) fans: Fans,
    /// Moved or merged in this pass.
    pub(super) touched: Vec<bool>,
    pub(super) buckets: Buckets,
    /// The triangles re-bucketed since the candidates were last looked for.
    pub(super) changes: Changes,
}

/// The bucket keys a decision read: the smallest box of keys around them.
#[derive(Clone, Copy, Debug)]
pub(super) struct KeyBox {
    lo: [i64; 3],
    hi: [i64; 3],
}

impl Default for KeyBox {
    fn default() -> Self {
        KeyBox {
            lo: [i64::MAX; 3],
            hi: [i64::MIN; 3],
        }
    }
}

impl KeyBox {
    pub(super) fn add(&mut self, key: [i64; 3]) {
        for ((lo, hi), k) in self.lo.iter_mut().zip(&mut self.hi).zip(key) {
            *lo = (*lo).min(k);
            *hi = (*hi).max(k);
        }
    }

    /// Every key in the box.
    pub(super) fn keys(&self) -> impl Iterator<Item = [i64; 3]> + '_ {
        (self.lo[2]..=self.hi[2]).flat_map(move |z| {
            (self.lo[1]..=self.hi[1])
                .flat_map(move |y| (self.lo[0]..=self.hi[0]).map(move |x| [x, y, z]))
        })
    }
}

impl Work {
    pub(super) fn new(mesh: &TriangleMesh, cell: f64) -> Work {
        let positions: Vec<DVec3> = mesh.positions.par_iter().map(|p| p.as_dvec3()).collect();
        let triangles = mesh.triangles.clone();
        let buckets = Buckets::new(cell, triangles.len(), |t| {
            triangles[t].map(|v| positions[v as usize])
        });
        Work {
            fans: Fans::new(&triangles, positions.len()),
            touched: vec![false; positions.len()],
            buckets,
            changes: Changes::new(triangles.len()),
            surface: Surface {
                alive: vec![true; triangles.len()],
                normals: mesh.normals.clone(),
                positions,
                triangles,
            },
        }
    }

    /// Live triangles around `v`.
    pub(super) fn fan(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        (self.fans.of(v)).filter(|&t| self.surface.alive[t as usize])
    }

    /// Neighbours of `v` (sorted, unique).
    pub(super) fn neighbours(&self, v: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self
            .fan(v)
            .flat_map(|t| self.surface.triangles[t as usize])
            .filter(|&w| w != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    pub(super) fn position(&self, v: u32) -> DVec3 {
        self.surface.positions[v as usize]
    }

    pub(super) fn corners(&self, t: u32) -> [DVec3; 3] {
        self.surface.triangles[t as usize].map(|v| self.position(v))
    }

    /// Twice the area vector of triangle `t`, with vertex `moved` (if any) at `to`.
    pub(super) fn normal(&self, t: u32, moved: &[u32], to: DVec3) -> DVec3 {
        let p = self.surface.triangles[t as usize].map(|v| {
            if moved.contains(&v) {
                to
            } else {
                self.position(v)
            }
        });
        (p[1] - p[0]).cross(p[2] - p[0])
    }

    pub(super) fn area(&self, t: u32) -> f64 {
        self.surface.area(t)
    }

    /// Triangle `t` with the vertices in `from` renamed `into`, placed at `to`.
    pub(super) fn moved(
        &self,
        t: u32,
        from: &[u32],
        into: u32,
        to: DVec3,
    ) -> ([u32; 3], [DVec3; 3]) {
        let ids =
            self.surface.triangles[t as usize].map(|v| if from.contains(&v) { into } else { v });
        let at = ids.map(|v| if v == into { to } else { self.position(v) });
        (ids, at)
    }

    /// Some proposed triangle meets another, or a live triangle nearby other than those in
    /// `changing`. The buckets read are added to `reads`.
    pub(super) fn crosses(
        &self,
        proposed: &[([u32; 3], [DVec3; 3])],
        changing: &[u32],
        reads: &mut KeyBox,
    ) -> bool {
        let margin = self.buckets.margin();
        let among = proposed.iter().enumerate().any(|(k, &(ids, at))| {
            (proposed[k + 1..].iter())
                .any(|&(other, there)| triangles_meet(at, ids, there, other, margin))
        });
        let corners: Vec<[DVec3; 3]> = proposed.iter().map(|&(_, at)| at).collect();
        among
            || self.buckets.any_near(
                &corners,
                |key| reads.add(key),
                |k, u| {
                    if changing.contains(&u) || !self.surface.alive[u as usize] {
                        return false;
                    }
                    let other = self.surface.triangles[u as usize];
                    let there = other.map(|v| self.position(v));
                    triangles_meet(proposed[k].1, proposed[k].0, there, other, margin)
                },
            )
    }

    /// Adds the buckets of `v`'s live triangles to `reads`.
    pub(super) fn note_fan(&self, v: u32, reads: &mut KeyBox) {
        for t in self.fan(v) {
            reads.add(self.buckets.key_of_triangle(t));
        }
    }

    /// Re-buckets the triangles around `v`, updates their boxes, and notes them as changed
    /// (every step calls this for every live triangle whose corners it renamed or moved).
    pub(super) fn rebucket(&mut self, v: u32) {
        let fan: Vec<u32> = self.fan(v).collect();
        for t in fan {
            let c = self.corners(t);
            self.buckets.update(t, c);
            self.changes.note(t);
        }
    }
}

impl Surface {
    pub(super) fn area(&self, t: u32) -> f64 {
        let p = self.triangles[t as usize].map(|v| self.positions[v as usize]);
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    }
}
