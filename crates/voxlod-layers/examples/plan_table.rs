//! The optimal layer plans of paper §3 (equations 4–6) for both filters: for 1 to 10 layers,
//! the error ∫₀¹ |p − d| dx of the optimum, and the isodensities and translucencies.
//!
//!     cargo run --release -p voxlod-layers --example plan_table

use voxlod_layers::optimal_plan;
use voxlod_sampling::Filter;

fn main() {
    for filter in [Filter::Hypercone, Filter::GAUSSIAN] {
        println!("{} filter", filter.name());
        println!(
            "{:>7} {:>10}  isodensities (translucencies)",
            "layers", "error"
        );
        for n in 1..=10 {
            let plan = optimal_plan(&filter, n);
            let layers: Vec<String> = plan
                .layers
                .iter()
                .map(|l| format!("{:.4} ({:.3})", l.isodensity, l.translucency))
                .collect();
            println!(
                "{n:>7} {:>10.6}  {}",
                plan.achieved_error,
                layers.join(", ")
            );
        }
        println!();
    }
}
