//! Rasterizer properties that can fail: exact coverage of known shapes, supersampled edge
//! coverage, the z-buffer, the blending order, thick lines and points, perspective size,
//! independence from the thread count, refused bad input.

use glam::{DVec3, Vec3};
use voxlod_core::{Bounds, TriangleMesh};
use voxlod_render::{
    render, Camera, Image, LineItem, MeshItem, PointItem, Projection, RenderError, RenderOptions,
    Scene,
};

/// A square in the plane z = `z`, corners (x0, y0)–(x1, y1), facing +z.
fn square(x0: f32, y0: f32, x1: f32, y1: f32, z: f32) -> TriangleMesh {
    TriangleMesh::new(
        vec![
            Vec3::new(x0, y0, z),
            Vec3::new(x1, y0, z),
            Vec3::new(x1, y1, z),
            Vec3::new(x0, y1, z),
        ],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

/// Looking down -z at [-1, 1]² with an image of `size` pixels: one pixel is 2/size units.
fn top_camera(size: u32) -> Camera {
    let mut cam = Camera::fit(
        DVec3::new(0.0, 0.0, -1.0),
        &Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
        size,
        size,
        None,
    )
    .unwrap();
    cam.projection = Projection::Orthographic { half_height: 1.0 };
    cam
}

fn covered(img: &Image) -> f64 {
    img.coverage.iter().map(|&c| c as f64).sum()
}

#[test]
fn coverage_equals_projected_area() {
    // A square of 0.5 × 0.75 units at 64 px: 16 × 24 = 384 pixels, placed off the pixel grid.
    let mesh = square(-0.3013, -0.2071, 0.1987, 0.5429, 0.0);
    let cam = top_camera(64);
    for n in [1, 4] {
        let img = render(
            &Scene {
                meshes: vec![MeshItem::opaque(&mesh, [1.0; 3])],
                ..Default::default()
            },
            &cam,
            &RenderOptions {
                supersample: n,
                ..Default::default()
            },
        )
        .unwrap();
        let c = covered(&img);
        assert!((c - 384.0).abs() < 24.0 / n as f64, "n={n}: {c}");
    }
}

#[test]
fn supersampled_edge_pixels_get_fractional_coverage() {
    // The square's left edge at x = 0.25 px into a pixel column: with 16×16 samples the
    // column's pixels are 3/4 covered.
    let size = 32u32;
    let px = 2.0 / size as f32;
    let x0 = -1.0 + 10.25 * px;
    let mesh = square(x0, -0.5, 0.5, 0.5, 0.0);
    let img = render(
        &Scene {
            meshes: vec![MeshItem::opaque(&mesh, [1.0; 3])],
            ..Default::default()
        },
        &top_camera(size),
        &RenderOptions::reference(),
    )
    .unwrap();
    let c = img.coverage[img.index(10, 16)];
    assert!((c - 0.75).abs() < 1.0 / 16.0 + 1e-6, "{c}");
    assert_eq!(img.coverage[img.index(11, 16)], 1.0);
    assert_eq!(img.coverage[img.index(9, 16)], 0.0);
}

#[test]
fn nearer_opaque_surfaces_win_whatever_the_order() {
    let near = square(-0.5, -0.5, 0.5, 0.5, 0.5);
    let far = square(-0.8, -0.8, 0.2, 0.2, -0.5);
    let cam = top_camera(32);
    for meshes in [
        vec![
            MeshItem::opaque(&near, [1.0, 0.0, 0.0]),
            MeshItem::opaque(&far, [0.0, 1.0, 0.0]),
        ],
        vec![
            MeshItem::opaque(&far, [0.0, 1.0, 0.0]),
            MeshItem::opaque(&near, [1.0, 0.0, 0.0]),
        ],
    ] {
        let options = RenderOptions {
            ambient: 1.0,
            ..Default::default()
        };
        let img = render(
            &Scene {
                meshes,
                ..Default::default()
            },
            &cam,
            &options,
        )
        .unwrap();
        // Pixel (12, 18) sees both (x ≈ −0.22, y ≈ −0.16): red wins.
        assert_eq!(img.rgb[img.index(12, 18)], [1.0, 0.0, 0.0]);
        // Pixel (4, 28) sees only the far one.
        assert_eq!(img.rgb[img.index(4, 28)], [0.0, 1.0, 0.0]);
    }
}

#[test]
fn blending_follows_the_given_order() {
    // Two overlapping translucent squares in one mesh; the order decides which is on top.
    let mut mesh = square(-0.5, -0.5, 0.5, 0.5, 0.0);
    let other = square(-0.2, -0.2, 0.8, 0.8, 0.1);
    mesh.positions.extend_from_slice(&other.positions);
    mesh.triangles
        .extend(other.triangles.iter().map(|t| t.map(|v| v + 4)));
    let palette = vec![[1.0, 0.0, 0.0, 0.5], [0.0, 0.0, 1.0, 0.5]];
    let tp = [0u16, 0, 1, 1];
    let cam = top_camera(32);
    let bg = [0.0, 0.0, 0.0];
    let options = RenderOptions {
        ambient: 1.0,
        background: bg,
        ..Default::default()
    };
    let draw = |order: &[u32]| {
        render(
            &Scene {
                meshes: vec![MeshItem::blended(&mesh, palette.clone(), &tp, order)],
                ..Default::default()
            },
            &cam,
            &options,
        )
        .unwrap()
    };
    let red_first = draw(&[0, 1, 2, 3]);
    let blue_first = draw(&[2, 3, 0, 1]);
    let p = red_first.index(16, 14);
    // Red then blue: 0.5·blue + 0.5·(0.5·red).
    assert_eq!(red_first.rgb[p], [0.25, 0.0, 0.5]);
    assert_eq!(blue_first.rgb[p], [0.5, 0.0, 0.25]);
    assert_eq!(red_first.coverage[p], 0.75);
    // Blended layers behind an opaque surface do not show.
    let wall = square(-1.0, -1.0, 1.0, 1.0, 0.5);
    let img = render(
        &Scene {
            meshes: vec![
                MeshItem::blended(&mesh, palette.clone(), &tp, &[0, 1, 2, 3]),
                MeshItem::opaque(&wall, [0.0, 1.0, 0.0]),
            ],
            ..Default::default()
        },
        &cam,
        &options,
    )
    .unwrap();
    assert_eq!(img.rgb[p], [0.0, 1.0, 0.0]);
}

#[test]
fn thick_lines_and_points_cover_their_area() {
    let cam = top_camera(64);
    let positions = vec![
        Vec3::new(-0.5, 0.0, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.5, 0.5, 0.0),
    ];
    let lines = [[0u32, 1]];
    let img = render(
        &Scene {
            lines: vec![LineItem {
                positions: &positions,
                lines: &lines,
                color: [1.0; 3],
                width: 3.0,
            }],
            ..Default::default()
        },
        &cam,
        &RenderOptions::reference(),
    )
    .unwrap();
    // 1 unit = 32 px long, 3 px wide.
    let c = covered(&img);
    assert!((c - 96.0).abs() < 1.0, "{c}");
    let points = [2u32];
    let img = render(
        &Scene {
            points: vec![PointItem {
                positions: &positions,
                points: &points,
                color: [1.0; 3],
                size: 4.0,
            }],
            ..Default::default()
        },
        &cam,
        &RenderOptions::reference(),
    )
    .unwrap();
    let c = covered(&img);
    assert!((c - 16.0).abs() < 0.5, "{c}");
}

fn cube() -> TriangleMesh {
    let mut m = voxlod_testkit::shapes::unit_cube();
    m.compute_vertex_normals();
    m
}

#[test]
fn perspective_draws_nearer_things_larger() {
    let near = cube();
    let mut far = cube();
    for p in &mut far.positions {
        p.x += 3.0;
        p.z -= 6.0;
    }
    let scene = Scene {
        meshes: vec![MeshItem::opaque(&near, [1.0; 3])],
        ..Default::default()
    };
    let scene_far = Scene {
        meshes: vec![MeshItem::opaque(&far, [1.0; 3])],
        ..Default::default()
    };
    let both = Bounds::new(DVec3::new(0.0, 0.0, -6.0), DVec3::new(4.0, 1.0, 1.0));
    let cam = Camera::fit(DVec3::new(0.0, 0.0, -1.0), &both, 128, 96, Some(50.0)).unwrap();
    let a = covered(&render(&scene, &cam, &RenderOptions::default()).unwrap());
    let b = covered(&render(&scene_far, &cam, &RenderOptions::default()).unwrap());
    assert!(a > 2.0 * b && b > 10.0, "near {a}, far {b}");
    // Orthographic: the same size.
    let cam = Camera::fit(DVec3::new(0.0, 0.0, -1.0), &both, 128, 96, None).unwrap();
    let a = covered(&render(&scene, &cam, &RenderOptions::default()).unwrap());
    let b = covered(&render(&scene_far, &cam, &RenderOptions::default()).unwrap());
    assert!((a - b).abs() <= 0.02 * a, "near {a}, far {b}");
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let mesh = cube();
    let cam = Camera::fit(DVec3::new(-0.4, -0.7, -0.5), &mesh.bounds(), 200, 150, None).unwrap();
    let scene = Scene {
        meshes: vec![MeshItem::opaque(&mesh, [0.8; 3])],
        ..Default::default()
    };
    let options = RenderOptions {
        supersample: 3,
        ..Default::default()
    };
    let many = render(&scene, &cam, &options).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render(&scene, &cam, &options).unwrap());
    assert_eq!(many, one);
}

#[test]
fn bad_input_is_refused() {
    let mesh = cube();
    let b = mesh.bounds();
    assert!(matches!(
        Camera::fit(DVec3::ZERO, &b, 10, 10, None),
        Err(RenderError::ZeroViewDirection)
    ));
    assert!(Camera::fit(DVec3::new(f64::NAN, 0.0, 1.0), &b, 10, 10, None).is_err());
    assert!(matches!(
        Camera::fit(DVec3::Z, &Bounds::EMPTY, 10, 10, None),
        Err(RenderError::EmptyScene)
    ));
    let scene = Scene {
        meshes: vec![MeshItem::opaque(&mesh, [1.0; 3])],
        ..Default::default()
    };
    let mut cam = Camera::fit(DVec3::Z, &b, 10, 10, None).unwrap();
    for n in [0, 33] {
        let o = RenderOptions {
            supersample: n,
            ..Default::default()
        };
        assert!(matches!(
            render(&scene, &cam, &o),
            Err(RenderError::BadSupersample(_))
        ));
    }
    cam.width = 0;
    assert!(matches!(
        render(&scene, &cam, &RenderOptions::default()),
        Err(RenderError::BadSize(0, 10))
    ));
    let mut broken = mesh.clone();
    broken.triangles[0][0] = 99;
    let scene = Scene {
        meshes: vec![MeshItem::opaque(&broken, [1.0; 3])],
        ..Default::default()
    };
    let cam = Camera::fit(DVec3::Z, &b, 10, 10, None).unwrap();
    assert!(render(&scene, &cam, &RenderOptions::default()).is_err());
}
