//! Scalar test fields shared with the peers' benchmark kit (`../shared/peers/peers.py`), so that
//! voxlod and VTK, SciPy or scikit-image can be timed on the same input: a signed field on an
//! n³ grid over [-1, 1]³, positive inside.
//!
//! - [`sphereflake_field`]: the maximum over the 820 spheres of `r - |p - c|`, -1 where no
//!   sphere is within two samples (the same construction, cut-off and default as the kit).
//! - [`gyroid_field`]: a thickened gyroid sheet inside a cube.
//!
//! Cost: O(n³) for the gyroid; for the flake, O(Σ over spheres of the samples in their boxes).

use rayon::prelude::*;
use voxlod_core::{Grid, Volume};

use voxlod_sampling::{sphereflake_spheres, SamplingError};

fn unit_grid(n: usize) -> Result<Grid, SamplingError> {
    let h = 2.0 / (n as f64 - 1.0);
    Ok(Grid::new([n; 3], [h; 3], [-1.0; 3])?)
}

fn coordinate(i: usize, n: usize) -> f32 {
    // numpy.linspace(-1, 1, n) in float32.
    (-1.0 + 2.0 * i as f64 / (n as f64 - 1.0)) as f32
}

/// The sphereflake's signed field on an n³ grid over [-1, 1]³.
pub fn sphereflake_field(n: usize) -> Result<Volume, SamplingError> {
    let grid = unit_grid(n)?;
    let mut volume = Volume::filled(grid, -1.0, "the sphereflake field")?;
    let h = 2.0 / (n as f64 - 1.0);
    let xs: Vec<f32> = (0..n).map(|i| coordinate(i, n)).collect();
    let spheres = sphereflake_spheres(3);
    let slice = n * n;
    volume
        .as_slice_mut()
        .par_chunks_mut(slice)
        .enumerate()
        .for_each(|(k, out)| {
            let z = xs[k];
            for &(c, r) in &spheres {
                // Samples within r + 2h of the centre along each axis, as the kit's searchsorted.
                let range = |a: usize| {
                    let lo = xs.partition_point(|&x| (x as f64) < c[a] - r - 2.0 * h);
                    let hi = xs.partition_point(|&x| (x as f64) < c[a] + r + 2.0 * h);
                    lo..hi
                };
                let (rx, ry, rz) = (range(0), range(1), range(2));
                if rx.is_empty() || ry.is_empty() || !rz.contains(&k) {
                    continue;
                }
                let dz = z as f64 - c.z;
                for j in ry {
                    let dy = xs[j] as f64 - c.y;
                    for i in rx.clone() {
                        let dx = xs[i] as f64 - c.x;
                        let d = (r - (dx * dx + dy * dy + dz * dz).sqrt()) as f32;
                        let v = &mut out[j * n + i];
                        if d > *v {
                            *v = d;
                        }
                    }
                }
            }
        });
    Ok(volume)
}

/// A gyroid sheet `0.3 - |sin kx cos ky + sin ky cos kz + sin kz cos kx|` (k = 3π) within the
/// cube `max |p| < 0.8`, shifted by -0.01 so that the outside is negative.
pub fn gyroid_field(n: usize) -> Result<Volume, SamplingError> {
    let grid = unit_grid(n)?;
    let mut volume = Volume::filled(grid, 0.0, "the gyroid field")?;
    let k = 3.0 * std::f32::consts::PI;
    let xs: Vec<f32> = (0..n).map(|i| coordinate(i, n)).collect();
    volume
        .as_slice_mut()
        .par_chunks_mut(n * n)
        .enumerate()
        .for_each(|(c, out)| {
            let z = xs[c];
            for j in 0..n {
                let y = xs[j];
                for i in 0..n {
                    let x = xs[i];
                    let g = (k * x).sin() * (k * y).cos()
                        + (k * y).sin() * (k * z).cos()
                        + (k * z).sin() * (k * x).cos();
                    let inside_cube = x.abs().max(y.abs()).max(z.abs()) < 0.8;
                    out[j * n + i] = (0.3 - g.abs()) * (inside_cube as u8 as f32) - 0.01;
                }
            }
        });
    Ok(volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_match_the_kits_sample_for_sample() {
        // `peers.py gen-volume --n 64` writes fields with exactly these numbers of positive
        // samples (24,086 of 262,144 for the flake, 24,204 for the gyroid).
        let positive = |v: &Volume| v.as_slice().iter().filter(|&&x| x > 0.0).count();
        assert_eq!(positive(&sphereflake_field(64).unwrap()), 24_086);
        assert_eq!(positive(&gyroid_field(64).unwrap()), 24_204);
    }
}
