//! `evaluate_asset` on a scene: the proxy beside the simplifiers, measured with its own baked
//! textures, and every level's draw calls beside the input's.

use voxlod::metrics::DistanceOptions;
use voxlod_eval::evaluate::{
    draw_calls, evaluate, evaluate_asset, report, Budgets, EvaluateOptions, ImageOptions, Method,
    PROXY,
};

/// The voxel pipeline, clustering and the proxy at two budgets, quick measures.
fn options() -> EvaluateOptions {
    EvaluateOptions {
        methods: vec![
            "voxel-hypercone".parse().unwrap(),
            "rossignac-borrel".parse().unwrap(),
            PROXY,
        ],
        budgets: Budgets::Explicit(vec![2000, 500]),
        distance: DistanceOptions::for_samples(5_000),
        images: ImageOptions::quick(),
        proxy_texture: 512,
        ..EvaluateOptions::quick()
    }
}

#[test]
fn the_proxy_of_a_scene_is_measured_with_its_own_textures_in_one_draw_call() {
    let scene = voxlod_testkit::assets::three_part_scene();
    assert_eq!(draw_calls(&scene), 3);
    let evaluation = evaluate_asset(&scene, &options(), |_, _| {}).unwrap();
    let names: Vec<&str> = evaluation.curves.iter().map(|c| c.method.name()).collect();
    assert_eq!(names, ["voxel-hypercone", "rossignac-borrel", "proxy"]);
    assert_eq!(evaluation.input.draw_calls, 3);
    for curve in &evaluation.curves {
        let (method, misses) = (curve.method, &curve.misses);
        assert_eq!(curve.points.len(), 2, "{method}: {misses:?}");
        for p in &curve.points {
            let a = p
                .appearance
                .expect("an asset's levels are measured for their looks");
            let silhouettes = p.image_difference.expect("measured").fraction;
            eprintln!(
                "{} at budget {}: {} triangles, Hausdorff {:.3} %, silhouettes {:.2} %, \
                 PSNR {:.2} dB, SSIM {:.4}",
                curve.method,
                p.budget,
                p.triangles,
                100.0 * p.hausdorff_fraction,
                100.0 * silhouettes,
                a.psnr,
                a.ssim
            );
            assert!(a.psnr.is_finite() && a.psnr > 10.0, "{a:?}");
            assert!(a.ssim > 0.0 && a.ssim < 1.0, "{a:?}");
            assert_eq!(p.draw_calls, 1, "{} at {}", curve.method, p.budget);
        }
    }
    let curve = |name: &str| {
        let found = evaluation.curves.iter().find(|c| c.method.name() == name);
        found.unwrap()
    };
    let (proxy, voxel) = (curve("proxy"), curve("voxel-hypercone"));
    for (p, v) in proxy.points.iter().zip(&voxel.points) {
        assert_eq!(p.budget, v.budget);
        let (pa, va) = (p.appearance.unwrap(), v.appearance.unwrap());
        // Baked textures keep the checkers that vertex colours at the budget blur.
        assert!(pa.psnr > va.psnr, "budget {}: {pa:?} {va:?}", p.budget);
        // The proxy is a closed level near its budget (once welded: its atlas splits
        // vertices), its parameter the budget; the two spheres that pass through each other
        // are one part of it, the sphere apart the other.
        assert!(p.closed_manifold);
        assert_eq!((p.components, p.genus), (2, Some(0)));
        assert_eq!(p.parameter, p.budget as f64);
        assert!(
            p.triangles.abs_diff(p.budget) * 10 <= p.budget,
            "{}",
            p.triangles
        );
    }
    let markdown = report::markdown(&evaluation, &report::ReportContext::default());
    assert!(markdown.contains("## proxy"), "{markdown}");
    assert!(
        markdown.contains("| draw calls | 3 | 1 | 1 | 1 |"),
        "{markdown}"
    );
    assert!(markdown.contains("takes 3 draw call(s)"), "{markdown}");
    let json = serde_json::to_value(&evaluation).unwrap();
    assert_eq!(json["input"]["draw_calls"], 3);
    assert_eq!(json["curves"][2]["method"], "proxy");
    assert_eq!(json["curves"][2]["points"][0]["draw_calls"], 1);
}

#[test]
fn a_mesh_without_looks_has_no_proxy() {
    let scene = voxlod_testkit::assets::three_part_scene();
    let options = EvaluateOptions {
        methods: vec!["rossignac-borrel".parse().unwrap(), PROXY],
        images: ImageOptions::off(),
        ..options()
    };
    let evaluation = evaluate(&scene.mesh.geometry(), &options, |_, _| {}).unwrap();
    let methods: Vec<Method> = evaluation.curves.iter().map(|c| c.method).collect();
    assert_eq!(methods, ["rossignac-borrel".parse().unwrap()]);
    assert!(evaluation.omitted.is_empty(), "{:?}", evaluation.omitted);
    assert_eq!(evaluation.input.draw_calls, 1);
    assert_eq!(evaluation.appearance_views, 0);
    for p in &evaluation.curves[0].points {
        assert_eq!(p.draw_calls, 1);
        assert!(p.appearance.is_none());
    }
}

#[test]
fn methods_are_named_with_the_proxy_among_them() {
    use voxlod_eval::evaluate::method_named;
    assert_eq!(method_named("proxy"), Ok(PROXY));
    assert_eq!(method_named("low-tan"), "low-tan".parse::<Method>());
    let unknown = method_named("gltfpack").unwrap_err();
    assert!(
        unknown.contains("'gltfpack'") && unknown.ends_with(", proxy)"),
        "{unknown}"
    );
    assert!(EvaluateOptions::standard().methods.contains(&PROXY));
    assert_eq!(EvaluateOptions::standard().proxy_texture, 1024);
}
