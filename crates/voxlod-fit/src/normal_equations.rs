//! The fitting's normal equations `M x = r` (crate docs): one sparse symmetric matrix for the
//! three coordinates, on the pattern of the level's vertex adjacency, solved by conjugate
//! gradients with a Jacobi preconditioner. Cost: O(F) to assemble, O(F) per CG step.

use voxlod_core::glam::DVec3;

/// The matrix (compressed rows: each vertex's neighbours and itself, sorted) and the three
/// right-hand sides.
pub(crate) struct NormalEquations {
    row_start: Vec<usize>,
    columns: Vec<u32>,
    values: Vec<f64>,
    rhs: Vec<DVec3>,
    /// The level's edges (i < j), for the springs.
    edges: Vec<(u32, u32)>,
}

/// Conjugate-gradient steps at most, and the residual (relative to the right-hand side) at
/// which the solve stops.
const MAX_STEPS: usize = 400;
const TOLERANCE: f64 = 1e-10;

impl NormalEquations {
    /// The pattern for `vertices` vertices and `triangles`, all values zero.
    pub(crate) fn new(vertices: usize, triangles: &[[u32; 3]]) -> NormalEquations {
        let mut edges: Vec<(u32, u32)> = (triangles.iter())
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(i, j)| (i.min(j), i.max(j)))
            .filter(|(i, j)| i != j)
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let mut neighbours: Vec<Vec<u32>> = (0..vertices as u32).map(|v| vec![v]).collect();
        for &(i, j) in &edges {
            neighbours[i as usize].push(j);
            neighbours[j as usize].push(i);
        }
        let mut row_start = Vec::with_capacity(vertices + 1);
        let mut columns = Vec::new();
        row_start.push(0);
        for mut row in neighbours {
            row.sort_unstable();
            columns.extend(row);
            row_start.push(columns.len());
        }
        NormalEquations {
            values: vec![0.0; columns.len()],
            rhs: vec![DVec3::ZERO; vertices],
            row_start,
            columns,
            edges,
        }
    }

    /// All values and right-hand sides back to zero.
    pub(crate) fn clear(&mut self) {
        self.values.fill(0.0);
        self.rhs.fill(DVec3::ZERO);
    }

    /// The term `weight · |Σ b_k x_(corner k) − s|²`.
    pub(crate) fn add_point(&mut self, corners: [u32; 3], b: DVec3, s: DVec3, weight: f64) {
        let b = b.to_array();
        for k in 0..3 {
            for l in 0..3 {
                *self.entry(corners[k], corners[l]) += weight * b[k] * b[l];
            }
            self.rhs[corners[k] as usize] += s * (weight * b[k]);
        }
    }

    /// The term `weight · |x_v − c|²`.
    pub(crate) fn add_vertex(&mut self, v: usize, c: DVec3, weight: f64) {
        *self.entry(v as u32, v as u32) += weight;
        self.rhs[v] += c * weight;
    }

    /// The springs `total / edges · |x_i − x_j|²` over every edge.
    pub(crate) fn add_springs(&mut self, total: f64) {
        let w = total / self.edges.len().max(1) as f64;
        for k in 0..self.edges.len() {
            let (i, j) = self.edges[k];
            *self.entry(i, i) += w;
            *self.entry(j, j) += w;
            *self.entry(i, j) -= w;
            *self.entry(j, i) -= w;
        }
    }

    fn entry(&mut self, row: u32, column: u32) -> &mut f64 {
        let range = self.row_start[row as usize]..self.row_start[row as usize + 1];
        let at = self.columns[range.clone()]
            .binary_search(&column)
            .expect("an edge of the level");
        &mut self.values[range.start + at]
    }

    fn multiply(&self, x: &[DVec3], out: &mut [DVec3]) {
        for (row, out) in out.iter_mut().enumerate() {
            let range = self.row_start[row]..self.row_start[row + 1];
            *out = (self.columns[range.clone()].iter().zip(&self.values[range]))
                .map(|(&c, &v)| x[c as usize] * v)
                .sum();
        }
    }

    fn diagonal(&self) -> Vec<f64> {
        (0..self.rhs.len())
            .map(|row| {
                let range = self.row_start[row]..self.row_start[row + 1];
                let at = self.columns[range.clone()]
                    .binary_search(&(row as u32))
                    .expect("the diagonal is in the pattern");
                self.values[range.start + at]
            })
            .collect()
    }
}

/// The solution of `equations` from `start`: the three coordinates at once (one matrix),
/// each coordinate's CG steps on its own scalars.
pub(crate) fn solve(equations: &NormalEquations, start: &[DVec3]) -> Vec<DVec3> {
    let inverse: Vec<f64> = (equations.diagonal().iter())
        .map(|&d| if d > 0.0 { 1.0 / d } else { 1.0 })
        .collect();
    let dot = |a: &[DVec3], b: &[DVec3]| -> DVec3 { a.iter().zip(b).map(|(x, y)| *x * *y).sum() };
    let precondition =
        |r: &[DVec3]| -> Vec<DVec3> { r.iter().zip(&inverse).map(|(r, d)| *r * *d).collect() };
    let mut x = start.to_vec();
    let mut ax = vec![DVec3::ZERO; x.len()];
    equations.multiply(&x, &mut ax);
    let mut r: Vec<DVec3> = (equations.rhs.iter().zip(&ax))
        .map(|(b, a)| *b - *a)
        .collect();
    let limit = dot(&equations.rhs, &equations.rhs) * (TOLERANCE * TOLERANCE);
    let mut z = precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut ap = vec![DVec3::ZERO; x.len()];
    for _ in 0..MAX_STEPS {
        if dot(&r, &r).cmple(limit).all() {
            break;
        }
        equations.multiply(&p, &mut ap);
        let pap = dot(&p, &ap);
        // A coordinate already solved has p = 0: its step is zero, not 0/0.
        let alpha = DVec3::select(pap.cmpgt(DVec3::ZERO), rz / pap, DVec3::ZERO);
        for k in 0..x.len() {
            x[k] += p[k] * alpha;
            r[k] -= ap[k] * alpha;
        }
        z = precondition(&r);
        let next = dot(&r, &z);
        let beta = DVec3::select(rz.cmpgt(DVec3::ZERO), next / rz, DVec3::ZERO);
        for k in 0..x.len() {
            p[k] = z[k] + p[k] * beta;
        }
        rz = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn springs_and_vertex_terms_solve_to_the_weighted_mean() {
        // A triangle with its vertices held at three targets (weight 1) and springs: the
        // solution is symmetric, each vertex pulled towards the others' mean.
        let mut eq = NormalEquations::new(3, &[[0, 1, 2]]);
        let targets = [DVec3::ZERO, DVec3::X * 3.0, DVec3::Y * 3.0];
        for (v, &t) in targets.iter().enumerate() {
            eq.add_vertex(v, t, 1.0);
        }
        eq.add_springs(3.0); // 1 per edge
        let x = solve(&eq, &[DVec3::ZERO; 3]);
        // (1 + 2) x_v − Σ_(others) x_u = t_v: summed, Σ x = Σ t, so x_v = (t_v + Σ t) / 4.
        for v in 0..3 {
            let others: DVec3 = (0..3).filter(|&u| u != v).map(|u| x[u]).sum();
            let residual = x[v] * 3.0 - others - targets[v];
            assert!(residual.length() < 1e-8, "{v}: {residual}");
        }
        assert!(
            (x[1] - DVec3::new(1.5, 0.75, 0.0)).length() < 1e-8,
            "{}",
            x[1]
        );
    }

    #[test]
    fn a_point_term_pulls_the_corners_by_their_coordinates() {
        // One triangle, its corners held in place weakly, a sample at the centroid lifted by
        // 1 in z with a strong weight: all three corners rise (nearly) together.
        let mut eq = NormalEquations::new(3, &[[0, 1, 2]]);
        let corners = [DVec3::ZERO, DVec3::X, DVec3::Y];
        for (v, &c) in corners.iter().enumerate() {
            eq.add_vertex(v, c, 1e-6);
        }
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        eq.add_point([0, 1, 2], DVec3::splat(1.0 / 3.0), centroid + DVec3::Z, 1.0);
        let x = solve(&eq, &corners);
        let lifted = (x[0] + x[1] + x[2]) / 3.0;
        assert!((lifted.z - 1.0).abs() < 1e-4, "{lifted}");
    }
}
