//! What an evaluation runs and how: the methods, the triangle budgets, the measurements, and
//! the bounds of each method's search.

use voxlod::metrics::DistanceOptions;

use super::images::ImageOptions;
use crate::methods::{Method, SearchLimits};

/// Which triangle counts to aim at.
#[derive(Clone, Debug, PartialEq)]
pub enum Budgets {
    /// Half the input's triangles, then halving `count` times in all, stopping before `smallest`.
    Halving {
        /// How many budgets at most.
        count: usize,
        /// No budget below this many triangles.
        smallest: usize,
    },
    /// These triangle counts.
    Explicit(Vec<usize>),
}

impl Budgets {
    /// The budgets for an input of `triangles` triangles, largest first, without repeats.
    pub fn resolve(&self, triangles: usize) -> Vec<usize> {
        let mut list = match self {
            Budgets::Halving { count, smallest } => {
                let mut list = Vec::new();
                let mut b = triangles / 2;
                while list.len() < *count && b >= (*smallest).max(1) {
                    list.push(b);
                    b /= 2;
                }
                list
            }
            Budgets::Explicit(list) => list.iter().copied().filter(|&b| b > 0).collect(),
        };
        list.sort_unstable_by(|a, b| b.cmp(a));
        list.dedup();
        list
    }
}

/// How to evaluate (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct EvaluateOptions {
    /// The methods to run, in the order of the report ([`Method::ALL`], then the scene proxy
    /// [`super::PROXY`], by default). The proxy runs on assets with looks only
    /// ([`super::evaluate_asset`]); [`super::evaluate`] passes over it.
    pub methods: Vec<Method>,
    /// The triangle counts to aim at.
    pub budgets: Budgets,
    /// Samples per surface of each distance measurement.
    pub distance: DistanceOptions,
    /// A trial within this relative distance of its budget ends the search (0.1: ±10 %).
    pub tolerance: f64,
    /// A level further than this factor from its budget (either way) is not kept: the budget
    /// is out of the method's reach (more triangles than clustering can keep, say).
    pub max_miss_factor: f64,
    /// Most runs spent on one budget of one method.
    pub max_trials: usize,
    /// Highest voxel resolution tried.
    pub max_resolution: usize,
    /// Most clustering cells tried along the longest side.
    pub max_cells: u32,
    /// Quadrature lines per filter radius of the voxel pipeline (see `voxlod lod --help`).
    pub lines_per_radius: usize,
    /// The silhouette difference's views and image size.
    pub images: ImageOptions,
    /// Texels a side of each proxy level's textures ([`voxlod::ProxyOptions::for_triangles`]).
    pub proxy_texture: u32,
}

impl Default for EvaluateOptions {
    fn default() -> Self {
        EvaluateOptions::standard()
    }
}

impl EvaluateOptions {
    /// The bounds these options set on every method's search.
    pub fn search_limits(&self) -> SearchLimits {
        SearchLimits {
            max_resolution: self.max_resolution,
            max_cells: self.max_cells,
        }
    }

    /// Every method and the proxy with textures of 1024², eight halving budgets down to 100
    /// triangles, 100 000 samples per side.
    pub fn standard() -> Self {
        let mut methods = Method::ALL.to_vec();
        methods.push(super::PROXY);
        EvaluateOptions {
            methods,
            budgets: Budgets::Halving {
                count: 8,
                smallest: 100,
            },
            distance: DistanceOptions::standard(),
            tolerance: 0.1,
            max_miss_factor: 1.5,
            max_trials: 6,
            max_resolution: 512,
            max_cells: 4096,
            lines_per_radius: 4,
            images: ImageOptions::standard(),
            proxy_texture: 1024,
        }
    }

    /// Every method and the proxy with textures of 256², four budgets, 20 000 samples per
    /// side, a looser fit: for tests and a first look.
    pub fn quick() -> Self {
        EvaluateOptions {
            budgets: Budgets::Halving {
                count: 4,
                smallest: 50,
            },
            distance: DistanceOptions::for_samples(20_000),
            tolerance: 0.2,
            max_trials: 4,
            images: ImageOptions::quick(),
            proxy_texture: 256,
            ..EvaluateOptions::standard()
        }
    }
}
