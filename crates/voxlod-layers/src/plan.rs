//! Layer planning (paper §3, equations 4–6): how many translucent shells, at which isodensities.
//!
//! **The profile.** Near a surface that is locally planar, a filtered solid's density depends only
//! on the signed distance from the surface: `d(x) = half_space_density(x R, R)` (equation 5),
//! with `d(0) = 1/2` on the surface, falling to 0 at the filter's support radius R. We measure x
//! in units of R, so d and everything below depend on the filter's shape only, not on R. The
//! paper measures r from the innermost layer M; we measure it from the surface of the unfiltered
//! object (the 0.5 isodensity), since the optimal innermost layer sits slightly outside it.
//!
//! **The problem** (equation 6). Find the piecewise constant `p` with the fewest segments such
//! that `∫₀¹ |p(x) − d(x)| dx ≤ ε`. Each segment becomes one layer: the isosurface at its constant
//! level, with translucency `1 − level / m` (equation 4), m the innermost (largest) level.
//!
//! **The optimum, not a heuristic** (the paper only suggests a recursive sub-optimal split). For
//! a fixed segment `[a, b]` the best constant under the L1 norm is the median of d there, which,
//! d being monotone, is `d((a + b) / 2)`, and the segment then costs
//! `∫ₐᵐ d − ∫ₘᵇ d` with m the midpoint. Differentiating the total with respect to a breakpoint
//! gives the optimality condition `d(xᵢ) = (cᵢ + cᵢ₊₁) / 2`: the profile at every breakpoint is
//! the mean of the levels on either side. Given the first breakpoint x₁, that condition fixes
//! every later one (`cᵢ₊₁ = 2 d(xᵢ) − cᵢ`, `mᵢ₊₁ = d⁻¹(cᵢ₊₁)`, `xᵢ₊₁ = 2 mᵢ₊₁ − xᵢ`), and the
//! last breakpoint grows with x₁; so bisection on x₁ until `xₙ = 1` ("shooting") finds the
//! stationary point to machine precision. d is convex and decreasing for both filters, for which
//! the stationary point is the global minimum; the tests check it against dynamic programming
//! over a fine grid of breakpoints. The minimal count comes from increasing n from 1 until the
//! optimal error is within ε (the optimal error falls strictly with n).
//!
//! **Blending** (beyond the paper). A layer's translucency t is equation 4's; the alpha it is
//! blended with is a separate choice, [`Blending`]. Drawn with `α = 1 − t` ([`Blending::Direct`]),
//! a ray that grazes the object crosses every closed shell outside it twice (in and out) and
//! keeps `Π (1 − αᵢ)²` of the light: more opaque than equation 4 says, which widens the
//! silhouette. [`Blending::Composited`] (the default) solves for the alphas that make the
//! composite exact: a ray passing between shells j − 1 and j crosses shells j … n twice each, so
//! `Π_{i ≥ j} (1 − αᵢ)² = t_j` for every j, i.e. `α_j = 1 − √(t_j / t_{j+1})` with
//! `t_{n+1} = 1`. The innermost layer stays opaque either way; rays through the front of the
//! object end on it, so only silhouettes see the difference.
//!
//! **Cost.** For n segments: 60 bisection steps × n inversions of d (60 bisection steps each),
//! so planning 64 layers takes about 10⁷ evaluations of d in all — milliseconds.

use serde::Serialize;
use voxlod_sampling::Filter;

use crate::LayersError;

/// The most layers a plan may have.
pub const MAX_LAYERS: usize = 64;

/// How a layer's translucency becomes the alpha it is blended with (see the module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Blending {
    /// `α_j = 1 − √(t_j / t_{j+1})`: the composite of the closed shells has translucency t_j
    /// (equation 4) along every ray that passes between shells j − 1 and j.
    #[default]
    Composited,
    /// `α = 1 − t`: equation 4 applied to each layer on its own.
    Direct,
}

impl std::str::FromStr for Blending {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "composited" | "composite" => Ok(Blending::Composited),
            "direct" => Ok(Blending::Direct),
            other => Err(format!(
                "unknown blending '{other}': choose composited or direct"
            )),
        }
    }
}

/// The blend alphas of layers with translucencies `t` (innermost first).
pub fn blend_alphas(t: &[f64], blending: Blending) -> Vec<f64> {
    (0..t.len())
        .map(|j| match blending {
            Blending::Direct => 1.0 - t[j],
            Blending::Composited => {
                let next = t.get(j + 1).copied().unwrap_or(1.0);
                if next <= 0.0 {
                    1.0
                } else {
                    (1.0 - (t[j] / next).max(0.0).sqrt()).clamp(0.0, 1.0)
                }
            }
        })
        .collect()
}

/// What to plan for.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PlanOptions {
    /// The filter the volume was made with (its half-space profile is what the layers follow).
    pub filter: Filter,
    /// The bound ε on `∫₀¹ |p − d| dx`, x in units of the support radius (0.01 to 0.2 typical).
    pub error: f64,
    /// Refuse plans that would need more layers than this.
    pub max_layers: usize,
    /// How translucency becomes blend alpha.
    pub blending: Blending,
}

impl Default for PlanOptions {
    /// The hyper-cone with ε = 0.025 (five layers, as on the paper's bolt).
    fn default() -> Self {
        PlanOptions {
            filter: Filter::Hypercone,
            error: 0.025,
            max_layers: MAX_LAYERS,
            blending: Blending::Composited,
        }
    }
}

impl PlanOptions {
    /// Plan for `filter` within `error`, at most [`MAX_LAYERS`] layers, composited alphas.
    pub fn new(filter: Filter, error: f64) -> PlanOptions {
        PlanOptions {
            filter,
            error,
            ..Default::default()
        }
    }

    /// A coarse approximation: ε = 0.05.
    pub fn coarse(filter: Filter) -> PlanOptions {
        PlanOptions::new(filter, 0.05)
    }

    /// A fine approximation: ε = 0.01.
    pub fn fine(filter: Filter) -> PlanOptions {
        PlanOptions::new(filter, 0.01)
    }
}

/// One planned layer: one segment of p.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PlannedLayer {
    /// The segment's constant: the isodensity of the layer's surface.
    pub isodensity: f64,
    /// `1 − isodensity / m` (equation 4): 0 for the innermost layer.
    pub translucency: f64,
    /// The alpha to blend the layer with (see [`Blending`]); 1 for the innermost layer.
    pub alpha: f64,
    /// Where the segment of the profile this layer stands for starts, in units of R.
    pub start: f64,
    /// Where the segment ends, in units of R.
    pub end: f64,
    /// Distance of the layer's surface outside the object's, in units of R (the midpoint).
    pub offset: f64,
    /// This segment's share of `∫ |p − d|`.
    pub error: f64,
}

/// A plan: the layers from the innermost (opaque) outwards, and the error it achieves.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LayerPlan {
    /// The filter whose profile the layers follow.
    pub filter: Filter,
    /// The ε asked for, when planned by error bound.
    pub error_bound: Option<f64>,
    /// How the alphas were made from the translucencies.
    pub blending: Blending,
    /// `∫₀¹ |p − d| dx` of this plan.
    pub achieved_error: f64,
    /// The layers, innermost (opaque) first.
    pub layers: Vec<PlannedLayer>,
}

impl LayerPlan {
    /// How many layers.
    pub fn len(&self) -> usize {
        self.layers.len()
    }

    /// Whether the plan has no layer (never, for a plan this crate makes).
    pub fn is_empty(&self) -> bool {
        self.layers.is_empty()
    }

    /// The isodensities, innermost first.
    pub fn isodensities(&self) -> Vec<f32> {
        self.layers.iter().map(|l| l.isodensity as f32).collect()
    }

    /// Recomputes the alphas for `blending`.
    pub fn set_blending(&mut self, blending: Blending) {
        let t: Vec<f64> = self.layers.iter().map(|l| l.translucency).collect();
        for (l, a) in self.layers.iter_mut().zip(blend_alphas(&t, blending)) {
            l.alpha = a;
        }
        self.blending = blending;
    }
}

/// The half-space profile d(x), x in units of the support radius (equation 5).
pub fn profile(filter: &Filter, x: f64) -> f64 {
    filter.half_space_density(x, 1.0)
}

/// `∫ₐᵇ d(x) dx` by 8-point Gauss–Legendre on panels no wider than 1/128 (d is a polynomial
/// for the hyper-cone and smooth for the Gaussian: the rule is exact to rounding).
pub fn profile_integral(filter: &Filter, a: f64, b: f64) -> f64 {
    const NODES: [(f64, f64); 4] = [
        (0.183_434_642_495_649_8, 0.362_683_783_378_362),
        (0.525_532_409_916_329, 0.313_706_645_877_887_3),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
    ];
    if b <= a {
        return -profile_integral(filter, b, a);
    }
    let panels = ((b - a) * 128.0).ceil().max(1.0) as usize;
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        let half = 0.5 * h;
        for &(x, w) in &NODES {
            sum += w * half * (profile(filter, mid - half * x) + profile(filter, mid + half * x));
        }
    }
    sum
}

/// d⁻¹(c) on [0, 1] by bisection: 0 for c ≥ d(0), 1 for c ≤ 0.
pub fn inverse_profile(filter: &Filter, c: f64) -> f64 {
    if c >= profile(filter, 0.0) {
        return 0.0;
    }
    if c <= 0.0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if profile(filter, mid) > c {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `∫ₐᵇ |c − d|` for a constant c, splitting at the crossing (d is decreasing).
pub fn segment_error(filter: &Filter, a: f64, b: f64, c: f64) -> f64 {
    let x = inverse_profile(filter, c).clamp(a, b);
    // Left of x, d ≥ c; right of it, d ≤ c.
    (profile_integral(filter, a, x) - c * (x - a)) + (c * (b - x) - profile_integral(filter, x, b))
}

/// `∫₀¹ |p − d|` for the step function with `levels[i]` on `[breaks[i], breaks[i + 1]]`.
pub fn plan_error(filter: &Filter, breaks: &[f64], levels: &[f64]) -> f64 {
    debug_assert_eq!(breaks.len(), levels.len() + 1);
    levels
        .iter()
        .enumerate()
        .map(|(i, &c)| segment_error(filter, breaks[i], breaks[i + 1], c))
        .sum()
}

/// The breakpoints after x₀ = 0 that the optimality condition gives from `x1`, and where the last
/// lands: `Err(())` when the chain overshoots 1 (or its levels reach 0) before n segments.
fn shoot(filter: &Filter, n: usize, x1: f64) -> Result<Vec<f64>, ()> {
    let mut xs = Vec::with_capacity(n + 1);
    xs.push(0.0);
    xs.push(x1);
    let mut c = profile(filter, 0.5 * x1);
    for i in 1..n {
        let x = xs[i];
        let next = 2.0 * profile(filter, x) - c;
        if next <= 0.0 || x >= 1.0 {
            return Err(());
        }
        let m = inverse_profile(filter, next);
        let x_next = 2.0 * m - x;
        if x_next <= x {
            return Err(());
        }
        xs.push(x_next);
        c = next;
    }
    Ok(xs)
}

/// The optimal plan with exactly `n` layers (1 ≤ n).
pub fn optimal_plan(filter: &Filter, n: usize) -> LayerPlan {
    assert!(n >= 1, "a plan has at least one layer");
    let mut breaks = if n == 1 {
        vec![0.0, 1.0]
    } else {
        // x_n(x₁) increases with x₁: bisect for x_n = 1 (x₁ = 1 always overshoots).
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let mut best = None;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            match shoot(filter, n, mid) {
                Ok(xs) if xs[n] < 1.0 => {
                    lo = mid;
                    best = Some(xs);
                }
                _ => hi = mid,
            }
        }
        let mut xs = best.unwrap_or_else(|| uniform_breaks(n));
        xs[n] = 1.0;
        xs
    };
    // Guard against a chain squeezed by rounding: breakpoints must increase.
    if breaks.windows(2).any(|w| w[1] <= w[0]) {
        breaks = uniform_breaks(n);
    }
    plan_from_breaks(filter, &breaks, None)
}

fn uniform_breaks(n: usize) -> Vec<f64> {
    (0..=n).map(|i| i as f64 / n as f64).collect()
}

/// The plan whose segments are `[breaks[i], breaks[i + 1]]`, each at its median level.
pub fn plan_from_breaks(filter: &Filter, breaks: &[f64], error_bound: Option<f64>) -> LayerPlan {
    let n = breaks.len() - 1;
    let levels: Vec<f64> = (0..n)
        .map(|i| profile(filter, 0.5 * (breaks[i] + breaks[i + 1])))
        .collect();
    let m = levels[0];
    let layers: Vec<PlannedLayer> = (0..n)
        .map(|i| {
            let (a, b) = (breaks[i], breaks[i + 1]);
            let mid = 0.5 * (a + b);
            PlannedLayer {
                isodensity: levels[i],
                translucency: if m > 0.0 {
                    (1.0 - levels[i] / m).clamp(0.0, 1.0)
                } else {
                    0.0
                },
                alpha: 0.0,
                start: a,
                end: b,
                offset: mid,
                // With the median level, the segment costs ∫ₐᵐ d − ∫ₘᵇ d.
                error: profile_integral(filter, a, mid) - profile_integral(filter, mid, b),
            }
        })
        .collect();
    let mut plan = LayerPlan {
        filter: *filter,
        error_bound,
        blending: Blending::Composited,
        achieved_error: layers.iter().map(|l| l.error).sum(),
        layers,
    };
    plan.set_blending(Blending::Composited);
    plan
}

/// The fewest layers whose optimal plan is within `options.error` (equation 6).
///
/// # Errors
///
/// [`LayersError::NonPositiveError`] for an ε that is not positive and finite,
/// [`LayersError::TooManyLayers`] when even `options.max_layers` layers do not reach it.
///
/// # Example
///
/// One layer at the median level of the hyper-cone's profile costs exactly 1/8, so ε = 0.126
/// needs one layer and ε = 0.12 two; the default ε = 0.025 needs five, at isodensities falling
/// outwards, the innermost opaque.
///
/// ```
/// use voxlod_layers::{plan_layers, PlanOptions};
/// use voxlod_sampling::Filter;
///
/// assert_eq!(plan_layers(&PlanOptions::new(Filter::Hypercone, 0.126))?.len(), 1);
/// assert_eq!(plan_layers(&PlanOptions::new(Filter::Hypercone, 0.12))?.len(), 2);
/// let plan = plan_layers(&PlanOptions::default())?;
/// assert_eq!(plan.len(), 5);
/// assert!(plan.achieved_error <= 0.025);
/// let iso = plan.isodensities();
/// assert!(iso.windows(2).all(|w| w[0] > w[1]));
/// assert_eq!(plan.layers[0].alpha, 1.0);
/// assert!(plan_layers(&PlanOptions::new(Filter::Hypercone, 0.0)).is_err());
/// # Ok::<(), voxlod_layers::LayersError>(())
/// ```
pub fn plan_layers(options: &PlanOptions) -> Result<LayerPlan, LayersError> {
    let bound = options.error;
    if !(bound.is_finite() && bound > 0.0) {
        return Err(LayersError::NonPositiveError(bound));
    }
    let max = options.max_layers.clamp(1, MAX_LAYERS);
    let mut last = None;
    for n in 1..=max {
        let mut plan = optimal_plan(&options.filter, n);
        if plan.achieved_error <= bound {
            plan.error_bound = Some(bound);
            plan.set_blending(options.blending);
            return Ok(plan);
        }
        last = Some(plan.achieved_error);
    }
    Err(LayersError::TooManyLayers {
        bound,
        max,
        achieved: last.unwrap_or(f64::NAN),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILTERS: [Filter; 2] = [Filter::Hypercone, Filter::GAUSSIAN];

    #[test]
    fn one_hypercone_layer_costs_an_eighth() {
        // D(x) = x/2 − x²/2 + x⁴/4 − x⁵/10; the median level d(1/2) costs 2 D(1/2) − D(1) = 1/8.
        let plan = optimal_plan(&Filter::Hypercone, 1);
        assert!((plan.achieved_error - 0.125).abs() < 1e-13, "{plan:?}");
        assert!((plan.layers[0].isodensity - (0.5 - 0.5 + 0.125 - 0.03125)).abs() < 1e-15);
        assert_eq!(plan.layers[0].translucency, 0.0);
    }

    #[test]
    fn integral_matches_the_closed_form() {
        let d = |x: f64| x / 2.0 - x * x / 2.0 + x.powi(4) / 4.0 - x.powi(5) / 10.0;
        for (a, b) in [(0.0, 1.0), (0.1, 0.37), (0.6, 0.99)] {
            let got = profile_integral(&Filter::Hypercone, a, b);
            assert!((got - (d(b) - d(a))).abs() < 1e-14, "{a}..{b}");
        }
    }

    /// Dynamic programming over breakpoints on a grid of `g` steps: an upper bound on the
    /// optimum that converges to it as the grid is refined.
    #[allow(clippy::needless_range_loop)]
    fn dp_optimum(filter: &Filter, n: usize, g: usize) -> f64 {
        let xs: Vec<f64> = (0..=g).map(|i| i as f64 / g as f64).collect();
        let prefix: Vec<f64> = {
            let mut p = vec![0.0; g + 1];
            for i in 1..=g {
                p[i] = p[i - 1] + profile_integral(filter, xs[i - 1], xs[i]);
            }
            p
        };
        // Segment cost with the median level, from prefix integrals and the half-way integral.
        let cost = |a: usize, b: usize| {
            let mid = 0.5 * (xs[a] + xs[b]);
            let left = profile_integral(filter, xs[a], mid);
            let whole = prefix[b] - prefix[a];
            left - (whole - left)
        };
        let mut best = vec![f64::INFINITY; g + 1];
        best[0] = 0.0;
        for _ in 0..n {
            let mut next = vec![f64::INFINITY; g + 1];
            for b in 1..=g {
                for a in 0..b {
                    if best[a].is_finite() {
                        next[b] = next[b].min(best[a] + cost(a, b));
                    }
                }
            }
            best = next;
        }
        best[g]
    }

    #[test]
    fn shooting_finds_the_global_optimum() {
        for filter in FILTERS {
            for n in [2, 3, 5] {
                let plan = optimal_plan(&filter, n);
                let dp = dp_optimum(&filter, n, 240);
                assert!(
                    plan.achieved_error <= dp + 1e-12,
                    "{filter:?} n={n}: shooting {} worse than the grid's {dp}",
                    plan.achieved_error
                );
                assert!(
                    dp <= plan.achieved_error * 1.002,
                    "{filter:?} n={n}: grid {dp} far from {}",
                    plan.achieved_error
                );
            }
        }
    }

    #[test]
    fn no_perturbation_of_the_breakpoints_helps() {
        for filter in FILTERS {
            let plan = optimal_plan(&filter, 6);
            let breaks: Vec<f64> = std::iter::once(0.0)
                .chain(plan.layers.iter().map(|l| l.end))
                .collect();
            let base = plan_error(&filter, &breaks, &plan_levels(&plan));
            assert!((base - plan.achieved_error).abs() < 1e-12);
            for i in 1..breaks.len() - 1 {
                for delta in [-1e-3, 1e-3, -1e-5, 1e-5] {
                    let mut b = breaks.clone();
                    b[i] += delta;
                    let moved = plan_from_breaks(&filter, &b, None);
                    assert!(
                        moved.achieved_error >= plan.achieved_error - 1e-13,
                        "{filter:?}: moving break {i} by {delta} lowered the error"
                    );
                }
            }
            // Any other level on a segment is worse than the median.
            for (i, l) in plan.layers.iter().enumerate() {
                let mut levels = plan_levels(&plan);
                levels[i] = l.isodensity * 1.01;
                assert!(plan_error(&filter, &breaks, &levels) > base);
            }
        }
    }

    fn plan_levels(plan: &LayerPlan) -> Vec<f64> {
        plan.layers.iter().map(|l| l.isodensity).collect()
    }

    #[test]
    fn fewest_layers_within_the_bound() {
        for filter in FILTERS {
            for eps in [0.2, 0.1, 0.05, 0.02, 0.01, 0.005] {
                let plan = plan_layers(&PlanOptions::new(filter, eps)).unwrap();
                let n = plan.len();
                assert!(plan.achieved_error <= eps);
                if n > 1 {
                    assert!(optimal_plan(&filter, n - 1).achieved_error > eps);
                }
                // Levels fall outwards, translucency rises, breakpoints tile [0, 1].
                assert_eq!(plan.layers[0].translucency, 0.0);
                assert!(plan.layers[0].start == 0.0 && plan.layers[n - 1].end == 1.0);
                for w in plan.layers.windows(2) {
                    assert!(w[1].isodensity < w[0].isodensity);
                    assert!(w[1].translucency > w[0].translucency);
                    assert_eq!(w[0].end, w[1].start);
                    // The optimality condition: d at the breakpoint is the mean of the levels.
                    let mean = 0.5 * (w[0].isodensity + w[1].isodensity);
                    if w[0].end < 0.9 {
                        assert!((profile(&filter, w[0].end) - mean).abs() < 1e-9);
                    }
                }
                assert!(plan.layers.iter().all(|l| l.isodensity < 0.5));
            }
        }
        // Optimal errors fall strictly with n.
        let errors: Vec<f64> = (1..12)
            .map(|n| optimal_plan(&Filter::GAUSSIAN, n).achieved_error)
            .collect();
        assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    }

    #[test]
    fn composited_alphas_reproduce_equation_4_along_grazing_rays() {
        let plan = optimal_plan(&Filter::Hypercone, 5);
        let n = plan.len();
        assert_eq!(plan.layers[0].alpha, 1.0);
        for j in 1..n {
            // A ray between shells j − 1 and j crosses shells j..n twice.
            let kept: f64 = plan.layers[j..]
                .iter()
                .map(|l| (1.0 - l.alpha).powi(2))
                .product();
            assert!(
                (kept - plan.layers[j].translucency).abs() < 1e-12,
                "layer {j}"
            );
        }
        let mut direct = plan.clone();
        direct.set_blending(Blending::Direct);
        for l in &direct.layers {
            assert_eq!(l.alpha, 1.0 - l.translucency);
        }
        assert!(direct.layers[1].alpha > plan.layers[1].alpha);
    }

    #[test]
    fn bad_bounds_are_refused() {
        for eps in [0.0, -0.1, f64::NAN] {
            let e = plan_layers(&PlanOptions::new(Filter::Hypercone, eps)).unwrap_err();
            assert!(e.to_string().contains("positive"), "{e}");
        }
        let e = plan_layers(&PlanOptions::new(Filter::Hypercone, 1e-5)).unwrap_err();
        assert!(e.to_string().contains("more than 64 layers"), "{e}");
        let ok = plan_layers(&PlanOptions::new(Filter::Hypercone, 10.0)).unwrap();
        assert_eq!(ok.len(), 1);
    }
}
