//! Axis-aligned boxes in world units: the extent of a mesh, of a grid, of a BVH node's
//! contents. The voxel paper (§2) sizes every level by the longest side of the object's box.
//! Cost: O(1) per operation, O(n) to bound n points.

use glam::{DVec3, Vec3};

/// An axis-aligned box in world units, in double precision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The corner with the smallest coordinates.
    pub min: DVec3,
    /// The corner with the largest coordinates.
    pub max: DVec3,
}

impl Bounds {
    /// The empty box: `min` above `max`, so that any point grows it.
    pub const EMPTY: Bounds = Bounds {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box from `min` to `max`, as given (not checked: `min` above `max` is empty).
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Bounds { min, max }
    }

    /// The smallest box holding every point; [`Bounds::EMPTY`] for no points.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Self {
        let mut b = Bounds::EMPTY;
        for p in points {
            b.grow(p.as_dvec3());
        }
        b
    }

    /// Grows the box to hold `p`.
    pub fn grow(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The smallest box holding both boxes.
    pub fn union(&self, other: &Bounds) -> Bounds {
        Bounds::new(self.min.min(other.min), self.max.max(other.max))
    }

    /// Holds no point: `min` is above `max` along some axis (or a coordinate is NaN).
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// The side lengths, zero for an empty box.
    pub fn size(&self) -> DVec3 {
        if self.is_empty() {
            DVec3::ZERO
        } else {
            self.max - self.min
        }
    }

    /// The midpoint of `min` and `max`.
    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// The length of the diagonal, from `min` to `max`.
    pub fn diagonal(&self) -> f64 {
        self.size().length()
    }

    /// The longest side.
    pub fn longest_extent(&self) -> f64 {
        self.size().max_element()
    }

    /// The box grown by `margin` on every side.
    pub fn expanded(&self, margin: f64) -> Bounds {
        Bounds::new(
            self.min - DVec3::splat(margin),
            self.max + DVec3::splat(margin),
        )
    }

    /// `p` lies inside or on the box.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The boxes share at least one point (touching counts).
    pub fn intersects(&self, other: &Bounds) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_and_measures() {
        let pts = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 5.0)];
        let b = Bounds::from_points(&pts);
        assert_eq!(b.min, DVec3::new(-1.0, 0.0, 3.0));
        assert_eq!(b.size(), DVec3::new(2.0, 2.0, 2.0));
        assert_eq!(b.longest_extent(), 2.0);
        assert!(Bounds::EMPTY.is_empty());
        assert_eq!(Bounds::EMPTY.size(), DVec3::ZERO);
        assert!(b.contains(DVec3::new(0.0, 1.0, 4.0)));
        assert!(!b.contains(DVec3::new(0.0, 3.0, 4.0)));
    }
}
