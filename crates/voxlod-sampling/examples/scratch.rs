use glam::Vec3;
use std::time::Instant;
use voxlod_contouring::{marching_cubes, ContourOptions};
use voxlod_core::{mesh_topology, TriangleMesh};
use voxlod_sampling::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (solid, opts): (Box<dyn Solid>, PyramidOptions) = if args[1] == "flake" {
        (
            Box::new(CsgSolid::new(sphereflake(3)).unwrap()),
            PyramidOptions::paper_table1(),
        )
    } else {
        let text = std::fs::read_to_string(&args[1]).unwrap();
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for l in text.lines() {
            let w: Vec<&str> = l.split_whitespace().collect();
            if w.first() == Some(&"v") {
                pos.push(Vec3::new(
                    w[1].parse().unwrap(),
                    w[2].parse().unwrap(),
                    w[3].parse().unwrap(),
                ));
            }
            if w.first() == Some(&"f") {
                let ids: Vec<u32> = w[1..]
                    .iter()
                    .map(|s| s.split('/').next().unwrap().parse::<u32>().unwrap() - 1)
                    .collect();
                for i in 1..ids.len() - 1 {
                    tris.push([ids[0], ids[i], ids[i + 1]]);
                }
            }
        }
        let t = Instant::now();
        let s = MeshSolid::new(&TriangleMesh::new(pos, tris)).unwrap();
        println!(
            "bvh {:.3}s exact={}",
            t.elapsed().as_secs_f64(),
            s.is_exact()
        );
        (
            Box::new(s),
            PyramidOptions::halving(256, 6, Filter::Hypercone),
        )
    };
    let total = Instant::now();
    let plans = plan_levels(&solid.bounds(), &opts).unwrap();
    for p in &plans {
        let t = Instant::now();
        let (vol, rep) =
            filtered_density(solid.as_ref(), &p.grid, &p.density_options(&opts)).unwrap();
        let ts = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let m = marching_cubes(&vol, &ContourOptions::default()).unwrap();
        let tc = t.elapsed().as_secs_f64();
        let topo = mesh_topology(&m);
        println!(
            "res {} dims {:?} sample {:.3}s mc {:.3}s tris {} closed {} genus {:?} maj {:?}",
            p.resolution,
            p.grid.dims,
            ts,
            tc,
            m.triangles.len(),
            topo.is_closed_manifold(),
            topo.genus,
            rep.majority
        );
    }
    println!("total {:.3}s", total.elapsed().as_secs_f64());
}
