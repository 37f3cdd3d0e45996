//! Cameras: orthographic and perspective, looking along a direction at a box.
//!
//! A camera maps world points to pixel coordinates (x right, y down, in pixels of the output
//! image, pixel centres at half-integers) and a depth key that grows away from the eye and is
//! affine in screen space (view depth for orthographic, `−1/depth` for perspective), so that it
//! can be interpolated linearly across a triangle for the z-test. The up vector is world +y,
//! or +z when looking (nearly) along y. [`Camera::fit`] frames a box: its bounding sphere fills
//! the shorter side of the image with a 5 % margin.
//!
//! Not in the papers: what the pictures of the layered shells (He et al. 1995 §3) and the
//! clustering baselines are drawn with. Cost: O(1) per projected point.

use glam::DVec3;
use serde::Serialize;
use voxlod_core::Bounds;

use crate::RenderError;

/// Orthographic or perspective.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum Projection {
    /// Parallel rays.
    Orthographic {
        /// Half the visible height in world units.
        half_height: f64,
    },
    /// Rays from the eye.
    Perspective {
        /// Vertical field of view in degrees.
        fov_y_degrees: f64,
        /// Distance from the eye of the near plane, in world units: nearer points are culled.
        near: f64,
    },
}

/// A camera with an image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the camera stands (for orthographic cameras, a point behind the scene).
    pub eye: DVec3,
    /// Unit view direction (eye to scene).
    pub forward: DVec3,
    /// Unit direction of the image's +x (right on screen).
    pub right: DVec3,
    /// Unit direction of the image's up (−y on screen).
    pub up: DVec3,
    /// Orthographic or perspective, with its size.
    pub projection: Projection,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// A point on screen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenPoint {
    /// Pixels from the left edge of the image.
    pub x: f64,
    /// Pixels from the top edge of the image.
    pub y: f64,
    /// Affine in screen space, larger is farther.
    pub depth_key: f64,
    /// 1 / view depth for perspective, 1 for orthographic (for perspective-correct shading).
    pub w_inv: f64,
}

/// Refuses a zero or non-finite direction.
pub fn check_direction(direction: DVec3) -> Result<DVec3, RenderError> {
    if !direction.is_finite() {
        return Err(RenderError::NonFiniteView(format!("{direction}")));
    }
    if direction.length_squared() == 0.0 {
        return Err(RenderError::ZeroViewDirection);
    }
    Ok(direction.normalize())
}

impl Camera {
    /// A camera looking along `direction` at `bounds`, framing it (see the module doc). With
    /// `perspective = Some(fov)` it is a perspective camera of that vertical field of view.
    pub fn fit(
        direction: DVec3,
        bounds: &Bounds,
        width: u32,
        height: u32,
        perspective: Option<f64>,
    ) -> Result<Camera, RenderError> {
        let forward = check_direction(direction)?;
        if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
            return Err(RenderError::EmptyScene);
        }
        let world_up = if forward.y.abs() > 0.99 {
            DVec3::Z
        } else {
            DVec3::Y
        };
        let right = forward.cross(world_up).normalize();
        let up = right.cross(forward);
        let centre = bounds.center();
        let radius = (0.5 * bounds.diagonal()).max(1e-12);
        let aspect = width as f64 / height as f64;
        let margin = 1.05;
        let (eye, projection) = match perspective {
            None => {
                let half_height = radius * margin / aspect.min(1.0);
                (
                    centre - forward * (3.0 * radius),
                    Projection::Orthographic { half_height },
                )
            }
            Some(fov) => {
                let fov = fov.clamp(1.0, 150.0);
                let half = (fov.to_radians() / 2.0).tan();
                // The sphere fits the shorter side.
                let half_short = half * aspect.min(1.0);
                let distance = radius * margin / half_short.atan().sin();
                (
                    centre - forward * distance,
                    Projection::Perspective {
                        fov_y_degrees: fov,
                        near: (distance - radius * 1.5).max(distance * 1e-3),
                    },
                )
            }
        };
        Ok(Camera {
            eye,
            forward,
            right,
            up,
            projection,
            width,
            height,
        })
    }

    /// Screen position of `p`; `None` before the near plane of a perspective camera.
    #[inline]
    pub fn project(&self, p: DVec3) -> Option<ScreenPoint> {
        let r = p - self.eye;
        let depth = r.dot(self.forward);
        let (w, h) = (self.width as f64, self.height as f64);
        let aspect = w / h;
        let (sx, sy, key, w_inv) = match self.projection {
            Projection::Orthographic { half_height } => {
                let half_width = half_height * aspect;
                (
                    r.dot(self.right) / half_width,
                    r.dot(self.up) / half_height,
                    depth,
                    1.0,
                )
            }
            Projection::Perspective {
                fov_y_degrees,
                near,
            } => {
                if depth < near {
                    return None;
                }
                let t = (fov_y_degrees.to_radians() / 2.0).tan();
                (
                    r.dot(self.right) / (depth * t * aspect),
                    r.dot(self.up) / (depth * t),
                    -1.0 / depth,
                    1.0 / depth,
                )
            }
        };
        Some(ScreenPoint {
            x: (sx + 1.0) * 0.5 * w,
            y: (1.0 - sy) * 0.5 * h,
            depth_key: key,
            w_inv,
        })
    }

    /// World units per pixel at the scene's centre distance (orthographic: everywhere).
    pub fn pixel_size_at(&self, p: DVec3) -> f64 {
        match self.projection {
            Projection::Orthographic { half_height } => 2.0 * half_height / self.height as f64,
            Projection::Perspective { fov_y_degrees, .. } => {
                let depth = (p - self.eye).dot(self.forward);
                2.0 * depth * (fov_y_degrees.to_radians() / 2.0).tan() / self.height as f64
            }
        }
    }

    /// Whether the projection is [`Projection::Perspective`].
    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitted_box_lands_on_screen_and_depth_grows_away() {
        let b = Bounds::new(DVec3::new(-1.0, -2.0, 0.0), DVec3::new(3.0, 1.0, 2.0));
        for persp in [None, Some(40.0)] {
            let cam = Camera::fit(DVec3::new(1.0, -0.5, -2.0), &b, 200, 100, persp).unwrap();
            for x in [b.min.x, b.max.x] {
                for y in [b.min.y, b.max.y] {
                    for z in [b.min.z, b.max.z] {
                        let s = cam.project(DVec3::new(x, y, z)).unwrap();
                        assert!(
                            s.x > 0.0 && s.x < 200.0 && s.y > 0.0 && s.y < 100.0,
                            "{s:?}"
                        );
                    }
                }
            }
            let c = b.center();
            let near = cam.project(c - cam.forward * 0.1).unwrap();
            let far = cam.project(c + cam.forward * 0.1).unwrap();
            assert!(far.depth_key > near.depth_key);
            // Up on screen is up in the world (y down on screen).
            let above = cam.project(c + cam.up * 0.1).unwrap();
            assert!(above.y < cam.project(c).unwrap().y);
        }
        assert!(Camera::fit(DVec3::ZERO, &b, 10, 10, None).is_err());
    }
}
