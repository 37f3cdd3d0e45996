//! A budget's level does not depend on the other budgets of the run, and meshoptimizer's two
//! reference methods reach their budgets.

use voxlod::metrics::DistanceOptions;
use voxlod_eval::evaluate::{evaluate, Budgets, EvaluateOptions, ImageOptions, Method};
use voxlod_testkit::shapes::torus;

fn run(methods: &[&str], budgets: Vec<usize>) -> voxlod_eval::evaluate::Evaluation {
    let mesh = torus(96, 48, 2.0, 0.7);
    let options = EvaluateOptions {
        methods: methods
            .iter()
            .map(|m| m.parse::<Method>().unwrap())
            .collect(),
        budgets: Budgets::Explicit(budgets),
        distance: DistanceOptions::for_samples(2_000),
        images: ImageOptions::off(),
        ..EvaluateOptions::quick()
    };
    evaluate(&mesh, &options, |_, _| {}).unwrap()
}

#[test]
fn a_budget_keeps_the_same_level_whatever_budgets_come_before_it() {
    let methods = ["rossignac-borrel", "voxel-hypercone", "meshopt-simplify"];
    let alone = run(&methods, vec![600]);
    let after_others = run(&methods, vec![4000, 1500, 600]);
    for (a, b) in alone.curves.iter().zip(&after_others.curves) {
        let pa = a
            .points
            .iter()
            .find(|p| p.budget == 600)
            .expect("600 alone");
        let pb = b
            .points
            .iter()
            .find(|p| p.budget == 600)
            .expect("600 after others");
        assert_eq!(
            (pa.parameter, pa.triangles),
            (pb.parameter, pb.triangles),
            "{}",
            a.method
        );
        assert_eq!(pa.hausdorff, pb.hausdorff, "{}", a.method);
    }
}

#[test]
fn meshoptimizer_methods_reach_their_budgets() {
    let evaluation = run(&["meshopt-simplify", "meshopt-sloppy"], vec![2000, 300]);
    for curve in &evaluation.curves {
        assert_eq!(
            curve.points.len(),
            2,
            "{}: {:?}",
            curve.method,
            curve.misses
        );
        for p in &curve.points {
            let miss = (p.triangles as f64 / p.budget as f64 - 1.0).abs();
            assert!(
                miss <= 0.10,
                "{} at {}: {}",
                curve.method,
                p.budget,
                p.triangles
            );
        }
    }
}
