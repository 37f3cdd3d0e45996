//! Scenes with looks made in code, for scene proxies' tests and benchmarks: a room of
//! textured furniture ([`room`]), a machine of two hundred small parts, some passing through
//! each other ([`machine`]), a tree with alpha-masked leaf cards ([`tree`]), a building with
//! window openings onto a hollow interior ([`building`]), props repeated by instance
//! transforms ([`props`]), and a machine of about a million triangles ([`scene_1m`]).
//!
//! Each is one [`Asset`] as a glTF reader gives it: every part in world space (an instanced
//! mesh repeated, transformed, as the reader flattens instancing), a [`Part`] per part, a
//! material per part from a handful, and generated PNG textures (checks, stripes, bricks,
//! rows of glyphs, grain, noise; module [`textures`]) sampled with repeat and linear
//! filtering, so that a misplaced texel shows. Closed pieces weld into closed, outward
//! surfaces (module [`pieces`]); leaf cards are open and double-sided.
//!
//! Flat faces are a few large cells (a box is 12 triangles or a little more), so that the
//! triangles are where curvature needs them (turned legs, domes, knobs, barrels, a flared
//! trunk) and a simplifier cannot meet a budget by merging coplanar cells alone.
//!
//! Every scene is deterministic (its random choices hash fixed seeds) and, but for
//! [`scene_1m`], holds 5 000 to 60 000 triangles; the facts each function states (parts,
//! materials, triangles) are checked by `tests/scenes.rs`.
//!
//! Cost: linear in the triangles, plus encoding a few 256² PNGs; a release build makes each
//! small scene in milliseconds and [`scene_1m`] in well under a second.

use std::f32::consts::{FRAC_PI_2, PI, TAU};
use std::sync::Arc;

use glam::{Affine3A, Quat, Vec3};
use voxlod_asset::{AlphaMode, Asset, AssetMesh, Image, Material, Part, Sampler, TextureRef};

pub mod pieces;
pub mod textures;

use pieces::{block, card, frustum, lathe, placed, profile, sphere};
use textures::{bricks, checks, glyphs, grain, leaves, speckle, stripes, unit};

/// A scene under construction: parts appended in world space with their materials.
#[derive(Default)]
pub struct SceneBuilder {
    asset: Asset,
}

impl SceneBuilder {
    /// An empty scene.
    pub fn new() -> Self {
        SceneBuilder::default()
    }

    /// A dielectric material of roughness 0.7 whose base colour is the PNG `png` (repeat,
    /// linear); with `mask`, double-sided and alpha-masked at 0.5. Returns its index.
    pub fn textured(&mut self, name: &str, png: Vec<u8>, mask: bool) -> u32 {
        self.asset.images.push(Image {
            name: format!("{name}.png"),
            mime: "image/png".into(),
            bytes: Arc::new(png),
        });
        let texture = TextureRef {
            image: self.asset.images.len() - 1,
            tex_coord: 0,
            transform: None,
            sampler: Sampler::default(),
        };
        self.material(Material {
            name: name.into(),
            base_color_texture: Some(texture),
            metallic: 0.0,
            roughness: 0.7,
            alpha_mode: if mask {
                AlphaMode::Mask
            } else {
                AlphaMode::Opaque
            },
            double_sided: mask,
            ..Material::default()
        })
    }

    /// A dielectric material of the linear colour `rgb`, emitting `emissive`. Returns its
    /// index.
    pub fn plain(&mut self, name: &str, rgb: [f32; 3], emissive: [f32; 3]) -> u32 {
        self.material(Material {
            name: name.into(),
            base_color: [rgb[0], rgb[1], rgb[2], 1.0],
            metallic: 0.0,
            roughness: 0.5,
            emissive,
            ..Material::default()
        })
    }

    /// Adds `material` as it is. Returns its index.
    pub fn material(&mut self, material: Material) -> u32 {
        self.asset.materials.push(material);
        self.asset.materials.len() as u32 - 1
    }

    /// Appends `piece` moved by `place` as the part `name` with `material`.
    pub fn add(&mut self, name: String, piece: &AssetMesh, place: Affine3A, material: u32) {
        let part = placed(piece, place);
        let mesh = &mut self.asset.mesh;
        let base = mesh.positions.len() as u32;
        self.asset.parts.push(Part {
            name,
            first_triangle: mesh.triangles.len() as u32,
            triangle_count: part.triangles.len() as u32,
        });
        mesh.positions.extend(&part.positions);
        mesh.normals.extend(&part.normals);
        mesh.uv[0].extend(&part.uv[0]);
        let shifted = part.triangles.iter().map(|t| t.map(|v| v + base));
        mesh.triangles.extend(shifted);
        let count = part.triangles.len();
        mesh.material.extend(std::iter::repeat_n(material, count));
    }

    /// The scene; panics if it breaks an invariant of [`Asset::validate`] (a fixture bug).
    pub fn finish(self) -> Asset {
        if let Err(e) = self.asset.validate() {
            panic!("a generated scene is invalid: {e}");
        }
        self.asset
    }
}

/// `place` as an affine map: scale, then rotation, then translation.
fn at(translation: Vec3, rotation: Quat, scale: Vec3) -> Affine3A {
    Affine3A::from_scale_rotation_translation(scale, rotation, translation)
}

/// A translation alone.
fn to(translation: Vec3) -> Affine3A {
    Affine3A::from_translation(translation)
}

/// A room 6 × 6 m with its floor at y = 0, open at the front (+z) and at the top, as a
/// diorama: the floor (wood grain), three walls (striped wallpaper), a rug (glyph rows), a
/// table (a checked top, four turned legs) with a checked vase on it, four chairs (seat, back,
/// four turned legs; grain) turned to face it, each with a checked cushion, a bookshelf (two
/// sides, three shelves) holding 24 books (glyph spines) with a globe beside it, and a lamp
/// (base, pole, curved shade, emissive bulb): 73 parts, 8 materials, 18 096 triangles.
pub fn room() -> Asset {
    let mut s = SceneBuilder::new();
    let wood = s.textured(
        "wood",
        grain(256, 4, [110, 70, 35, 255], [190, 140, 85, 255], 1),
        false,
    );
    let paper = s.textured(
        "wallpaper",
        stripes(
            256,
            16,
            &[
                [200, 190, 150, 255],
                [150, 60, 60, 255],
                [220, 215, 200, 255],
            ],
        ),
        false,
    );
    let rug = s.textured(
        "rug",
        glyphs(256, [150, 30, 40, 255], [240, 200, 80, 255], 2),
        false,
    );
    let cloth = s.textured(
        "tablecloth",
        checks(256, 32, [30, 60, 140, 255], [235, 235, 225, 255]),
        false,
    );
    let spines = s.textured(
        "book spines",
        glyphs(256, [235, 225, 200, 255], [20, 20, 60, 255], 3),
        false,
    );
    let shade = s.textured(
        "lamp shade",
        stripes(256, 24, &[[240, 220, 160, 255], [200, 120, 40, 255]]),
        false,
    );
    let metal = s.plain("brass", [0.6, 0.45, 0.15], [0.0; 3]);
    let bulb = s.plain("bulb", [1.0, 0.95, 0.8], [1.0, 0.85, 0.5]);
    let density = 1.0;
    s.add(
        "floor".into(),
        &block(Vec3::new(3.0, 0.05, 3.0), density, 1.0),
        to(Vec3::new(0.0, -0.05, 0.0)),
        wood,
    );
    let wall = block(Vec3::new(3.0, 1.4, 0.08), density, 1.0);
    for (name, place) in [
        ("back wall", to(Vec3::new(0.0, 1.4, -3.08))),
        (
            "left wall",
            at(
                Vec3::new(-3.08, 1.4, 0.0),
                Quat::from_rotation_y(FRAC_PI_2),
                Vec3::ONE,
            ),
        ),
        (
            "right wall",
            at(
                Vec3::new(3.08, 1.4, 0.0),
                Quat::from_rotation_y(-FRAC_PI_2),
                Vec3::ONE,
            ),
        ),
    ] {
        s.add(name.into(), &wall, place, paper);
    }
    s.add(
        "rug".into(),
        &block(Vec3::new(1.6, 0.01, 1.1), density, 0.5),
        to(Vec3::new(0.3, 0.01, 0.4)),
        rug,
    );
    furnish_table(&mut s, Vec3::new(0.3, 0.0, 0.4), wood, cloth);
    furnish_shelf(&mut s, Vec3::new(-1.6, 0.0, -2.7), wood, spines);
    furnish_lamp(&mut s, Vec3::new(2.3, 0.0, -2.3), metal, shade, bulb);
    s.finish()
}

/// The table at `centre` (on the floor) and four chairs around it.
fn furnish_table(s: &mut SceneBuilder, centre: Vec3, wood: u32, cloth: u32) {
    s.add(
        "table top".into(),
        &block(Vec3::new(0.9, 0.04, 0.55), 1.0, 1.0),
        to(centre + Vec3::new(0.0, 0.76, 0.0)),
        cloth,
    );
    let leg = lathe(&turned(0.72, 0.04, 12), 16, 2.0);
    for (k, (x, z)) in [(-0.8, -0.45), (0.8, -0.45), (-0.8, 0.45), (0.8, 0.45)]
        .into_iter()
        .enumerate()
    {
        s.add(
            format!("table leg {k}"),
            &leg,
            to(centre + Vec3::new(x, 0.36, z)),
            wood,
        );
    }
    let seat = block(Vec3::new(0.22, 0.03, 0.22), 1.0, 2.0);
    let back = block(Vec3::new(0.22, 0.3, 0.025), 1.0, 2.0);
    let chair_leg = lathe(&turned(0.44, 0.025, 10), 12, 2.0);
    let cushion = sphere(1.0, 32);
    for k in 0..4 {
        let angle = k as f32 * FRAC_PI_2;
        let turn = Quat::from_rotation_y(angle);
        let base = centre + turn * Vec3::new(0.0, 0.0, 1.0);
        let place = |offset: Vec3| at(base + turn * offset, turn, Vec3::ONE);
        s.add(
            format!("chair {k} seat"),
            &seat,
            place(Vec3::new(0.0, 0.47, 0.0)),
            wood,
        );
        s.add(
            format!("chair {k} back"),
            &back,
            place(Vec3::new(0.0, 0.8, 0.2)),
            wood,
        );
        for (l, (x, z)) in [(-0.19, -0.19), (0.19, -0.19), (-0.19, 0.19), (0.19, 0.19)]
            .into_iter()
            .enumerate()
        {
            s.add(
                format!("chair {k} leg {l}"),
                &chair_leg,
                place(Vec3::new(x, 0.22, z)),
                wood,
            );
        }
        let on_seat = base + turn * Vec3::new(0.0, 0.53, 0.0);
        let squash = Vec3::new(0.2, 0.045, 0.2);
        let place = at(on_seat, turn, squash);
        s.add(format!("chair {k} cushion"), &cushion, place, cloth);
    }
    let vase = lathe(
        &profile(24, |t| {
            let belly = (PI * t).sin().max(0.0).powf(1.5);
            [0.045 + 0.065 * belly + 0.02 * t.powi(4), 0.3 * t - 0.15]
        }),
        48,
        2.0,
    );
    let place = to(centre + Vec3::new(0.2, 0.95, -0.1));
    s.add("vase".into(), &vase, place, cloth);
}

/// A turned leg's profile along y, `length` long and about `radius` thick, with two beads.
fn turned(length: f32, radius: f32, points: u32) -> Vec<[f32; 2]> {
    profile(points, |t| {
        let bead = (3.0 * PI * t).sin().powi(2);
        [radius * (1.0 + 0.35 * bead - 0.2 * t), length * (t - 0.5)]
    })
}

/// A bookshelf against the back wall at `centre` (on the floor): two sides, three shelves,
/// eight books standing on each shelf.
fn furnish_shelf(s: &mut SceneBuilder, centre: Vec3, wood: u32, spines: u32) {
    let side = block(Vec3::new(0.02, 0.9, 0.15), 1.0, 2.0);
    for (k, x) in [-0.6f32, 0.6].into_iter().enumerate() {
        s.add(
            format!("shelf side {k}"),
            &side,
            to(centre + Vec3::new(x, 0.9, 0.0)),
            wood,
        );
    }
    let board = block(Vec3::new(0.58, 0.02, 0.15), 1.0, 2.0);
    for level in 0..3 {
        let y = 0.1 + 0.6 * level as f32;
        s.add(
            format!("shelf {level}"),
            &board,
            to(centre + Vec3::new(0.0, y, 0.0)),
            wood,
        );
        for b in 0..8u32 {
            let h = 0.18 + 0.08 * unit(b, level, 7);
            let w = 0.03 + 0.02 * unit(b, level, 8);
            let book = block(Vec3::new(w, h, 0.11), 1.0, 1.5);
            let x = -0.5 + 0.135 * b as f32;
            s.add(
                format!("book {level}.{b}"),
                &book,
                to(centre + Vec3::new(x, y + 0.02 + h, 0.02)),
                spines,
            );
        }
    }
    let globe = sphere(0.12, 48);
    let place = to(centre + Vec3::new(0.9, 0.12, 0.0));
    s.add("globe".into(), &globe, place, spines);
}

/// A floor lamp at `centre`: a base, a pole, a striped shade and an emissive bulb.
fn furnish_lamp(s: &mut SceneBuilder, centre: Vec3, metal: u32, shade: u32, bulb: u32) {
    let parts = [
        (
            "lamp base",
            lathe(
                &profile(8, |t| [0.22 - 0.06 * t * t, 0.04 * t - 0.02]),
                48,
                2.0,
            ),
            0.02,
            metal,
        ),
        (
            "lamp pole",
            frustum([0.02, 0.02, 1.5], 16, 2.0),
            0.79,
            metal,
        ),
        (
            "lamp shade",
            lathe(
                &profile(12, |t| [0.3 - 0.14 * t.sqrt(), 0.35 * t - 0.175]),
                64,
                1.0,
            ),
            1.55,
            shade,
        ),
        ("lamp bulb", sphere(0.08, 32), 1.45, bulb),
    ];
    for (name, piece, y, material) in parts {
        s.add(
            name.into(),
            &piece,
            to(centre + Vec3::new(0.0, y, 0.0)),
            material,
        );
    }
}

/// [`machine_with`] at detail 1: 54 272 triangles.
pub fn machine() -> Asset {
    machine_with(1.0)
}

/// A machine on a base plate 8 × 5: a 20 × 10 grid of cells, each holding one small part
/// (a housing box, a tilted block sunk into the plate, a domed boss or a knob sphere, by
/// the cell's hash), plus 12 pipes lying across the cells through the parts: 213 parts
/// (plate, 200 cell parts, 12 pipes), 6 materials (worn metal, hazard stripes, checked
/// panels, glyph labels, copper, red paint). `detail` scales the curved pieces'
/// tessellation (segments around, points along a profile), so triangles grow with its
/// square.
pub fn machine_with(detail: f32) -> Asset {
    let mut s = SceneBuilder::new();
    let metal = s.textured(
        "worn metal",
        speckle(256, [90, 95, 100, 255], [170, 175, 180, 255], 11),
        false,
    );
    let hazard = s.textured(
        "hazard",
        stripes(256, 20, &[[230, 190, 20, 255], [25, 25, 25, 255]]),
        false,
    );
    let panel = s.textured(
        "panel",
        checks(256, 16, [60, 110, 160, 255], [200, 210, 220, 255]),
        false,
    );
    let label = s.textured(
        "labels",
        glyphs(256, [240, 240, 230, 255], [10, 10, 10, 255], 12),
        false,
    );
    let copper = s.textured(
        "copper",
        grain(256, 8, [120, 60, 30, 255], [210, 130, 80, 255], 13),
        false,
    );
    let paint = s.plain("red paint", [0.6, 0.05, 0.04], [0.0; 3]);
    let density = 1.0;
    let segments = |n: f32| ((n * detail).round() as u32).max(6);
    s.add(
        "base plate".into(),
        &block(Vec3::new(4.0, 0.1, 2.5), density, 1.0),
        to(Vec3::new(0.0, -0.1, 0.0)),
        metal,
    );
    let materials = [hazard, panel, label, paint];
    for (i, j) in (0..20u32).flat_map(|i| (0..10u32).map(move |j| (i, j))) {
        let centre = Vec3::new(-3.8 + 0.4 * i as f32, 0.0, -2.3 + 0.5 * j as f32);
        let r = |k: u32| unit(i, j, 20 + k);
        let material = materials[(r(0) * 4.0) as usize % 4];
        let (name, piece, place) = match (r(1) * 4.0) as u32 {
            0 => {
                let half = Vec3::new(0.1 + 0.06 * r(2), 0.1 + 0.2 * r(3), 0.12 + 0.08 * r(4));
                let piece = block(half, density, 4.0);
                ("housing", piece, to(centre + Vec3::Y * half.y))
            }
            1 => {
                let half = Vec3::new(0.15, 0.08 + 0.1 * r(3), 0.1);
                let tilt = Quat::from_euler(glam::EulerRot::YXZ, TAU * r(2), 0.5 * r(4), 0.0);
                let piece = block(half, density, 4.0);
                ("tilted block", piece, at(centre, tilt, Vec3::ONE))
            }
            2 => {
                let (radius, height) = (0.08 + 0.07 * r(2), 0.15 + 0.35 * r(3));
                let dome = |t: f32| {
                    let t = 0.97 * t;
                    [radius * (1.0 - t.powi(4)).powf(0.25), height * (t - 0.5)]
                };
                let piece = lathe(&profile(segments(10.0), dome), segments(24.0), 3.0);
                ("boss", piece, to(centre + Vec3::Y * (0.5 * height)))
            }
            _ => {
                let radius = 0.1 + 0.06 * r(2);
                let piece = sphere(radius, segments(24.0));
                ("knob", piece, to(centre + Vec3::Y * (0.6 * radius)))
            }
        };
        s.add(format!("{name} {i}.{j}"), &piece, place, material);
    }
    for k in 0..12u32 {
        let (z, y) = (-2.3 + 0.42 * k as f32, 0.2 + 0.25 * unit(k, 0, 40));
        let pipe = frustum([0.05, 0.05, 7.6], segments(16.0), 2.0);
        let turn = Quat::from_rotation_z(FRAC_PI_2);
        let angle = Quat::from_rotation_y(0.15 * (unit(k, 1, 40) - 0.5));
        let place = at(Vec3::new(0.0, y, z), angle * turn, Vec3::ONE);
        s.add(format!("pipe {k}"), &pipe, place, copper);
    }
    s.finish()
}

/// A machine of about a million triangles: [`machine_with`] at detail 4.25, 988 124
/// triangles.
pub fn scene_1m() -> Asset {
    machine_with(4.25)
}

/// A tree: a tapering, flared trunk (bark grain) with six branches passing into it, and 480
/// leaf cards (thin open quads of two triangles, double-sided, alpha-masked at 0.5 with four
/// leaves each) scattered over an ellipsoid crown and turned at random: 487 parts, 2
/// materials, 5 952 triangles.
pub fn tree() -> Asset {
    let mut s = SceneBuilder::new();
    let bark = s.textured(
        "bark",
        grain(256, 1, [60, 40, 25, 255], [130, 100, 70, 255], 21),
        false,
    );
    let leaf = s.textured("leaves", leaves(256, 22), true);
    s.add(
        "trunk".into(),
        &lathe(
            &profile(32, |t| {
                let flare = 0.25 * (1.0 - t).powi(8);
                [
                    0.18 + 0.17 * (1.0 - t) + flare + 0.01 * (20.0 * t).sin(),
                    4.0 * t - 2.0,
                ]
            }),
            48,
            2.0,
        ),
        to(Vec3::new(0.0, 2.0, 0.0)),
        bark,
    );
    for k in 0..6u32 {
        let around = TAU * k as f32 / 6.0 + 0.4 * unit(k, 0, 23);
        let lift = 0.7 + 0.3 * unit(k, 1, 23);
        let turn = Quat::from_rotation_y(around) * Quat::from_rotation_z(-lift);
        let base = Vec3::new(0.0, 2.6 + 0.25 * k as f32, 0.0);
        let branch = lathe(
            &profile(10, |t| {
                [0.12 - 0.07 * t + 0.01 * (9.0 * t).sin(), 2.2 * (t - 0.5)]
            }),
            16,
            2.0,
        );
        let centre = base + turn * Vec3::new(0.0, 1.0, 0.0);
        s.add(
            format!("branch {k}"),
            &branch,
            at(centre, turn, Vec3::ONE),
            bark,
        );
    }
    let leaf_card = card(0.6, 0.6, 1);
    for k in 0..480u32 {
        let r = |c: u32| unit(k, c, 24);
        let (phi, cos_theta, depth) = (TAU * r(0), 2.0 * r(1) - 1.0, 0.55 + 0.45 * r(2).sqrt());
        let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
        let p = Vec3::new(sin_theta * phi.cos(), cos_theta, sin_theta * phi.sin()) * depth;
        let centre = Vec3::new(0.0, 4.3, 0.0) + p * Vec3::new(2.2, 1.5, 2.2);
        let turn = Quat::from_euler(
            glam::EulerRot::YXZ,
            TAU * r(3),
            PI * (r(4) - 0.5),
            PI * r(5),
        );
        s.add(
            format!("leaf card {k}"),
            &leaf_card,
            at(centre, turn, Vec3::ONE),
            leaf,
        );
    }
    s.finish()
}

/// The materials of [`building`], by use.
struct BuildingLooks {
    brick: u32,
    stone: u32,
    floor: u32,
    plaster: u32,
    roof: u32,
}

/// A three-storey building 8.5 × 6.5 × 9 with walls 0.25 thick: each floor of each wall a band
/// below the windows, a band above them and piers between window openings (3 a floor on the
/// long walls, 2 on the short ones), a stone sill under each opening; inside, three floor
/// slabs, a partition wall (between window columns) and two cabinets a floor, hollow between
/// them; a roof slab over all and four stone columns with entasis in front of the front wall,
/// through the roof's overhang: 113 parts, 5 materials (bricks, stone, floor grain, plaster
/// with glyph posters, roof checks), 8 096 triangles.
pub fn building() -> Asset {
    let mut s = SceneBuilder::new();
    let looks = building_looks(&mut s);
    let (t, half_x, half_z) = (0.25f32, 4.0f32, 3.0f32);
    let walls = [
        (
            "front",
            2.0 * half_x + 2.0 * t,
            3,
            Vec3::Z * (half_z + t / 2.0),
            0.0,
        ),
        (
            "back",
            2.0 * half_x + 2.0 * t,
            3,
            -Vec3::Z * (half_z + t / 2.0),
            PI,
        ),
        (
            "right",
            2.0 * half_z,
            2,
            Vec3::X * (half_x + t / 2.0),
            FRAC_PI_2,
        ),
        (
            "left",
            2.0 * half_z,
            2,
            -Vec3::X * (half_x + t / 2.0),
            -FRAC_PI_2,
        ),
    ];
    for (name, length, windows, centre, yaw) in walls {
        let frame = at(centre, Quat::from_rotation_y(yaw), Vec3::ONE);
        facade(&mut s, name, [length, t], windows, frame, &looks);
    }
    for floor in 0..3 {
        let y = 3.0 * floor as f32;
        let slab = block(Vec3::new(half_x - 0.01, 0.1, half_z - 0.01), 1.0, 1.0);
        s.add(
            format!("slab {floor}"),
            &slab,
            to(Vec3::Y * (y + 0.1)),
            looks.floor,
        );
        let partition = block(Vec3::new(0.08, 1.35, half_z - 0.05), 1.0, 1.0);
        let place = to(Vec3::new(1.4, y + 1.55, 0.0));
        s.add(
            format!("partition {floor}"),
            &partition,
            place,
            looks.plaster,
        );
        for (k, x) in [-2.5f32, 2.0].into_iter().enumerate() {
            let cabinet = block(Vec3::new(0.6, 0.5, 0.3), 1.0, 1.0);
            let place = to(Vec3::new(x, y + 0.7, -half_z + 0.4));
            s.add(format!("cabinet {floor}.{k}"), &cabinet, place, looks.stone);
        }
    }
    let roof = block(Vec3::new(half_x + 0.4, 0.15, half_z + 0.4), 1.0, 0.5);
    s.add("roof".into(), &roof, to(Vec3::Y * 9.15), looks.roof);
    let column = lathe(
        &profile(16, |t| {
            [0.18 - 0.04 * t + 0.03 * (PI * t).sin(), 9.0 * (t - 0.5)]
        }),
        32,
        1.0,
    );
    for (k, x) in [-3.9f32, -1.42, 1.42, 3.9].into_iter().enumerate() {
        let place = to(Vec3::new(x, 4.5, half_z + t + 0.2));
        s.add(format!("column {k}"), &column, place, looks.stone);
    }
    s.finish()
}

/// The materials of [`building`]: bricks, stone, floor grain, plaster with glyph posters,
/// roof checks.
fn building_looks(s: &mut SceneBuilder) -> BuildingLooks {
    BuildingLooks {
        brick: s.textured(
            "bricks",
            bricks(256, [150, 60, 40, 255], [200, 195, 185, 255], 31),
            false,
        ),
        stone: s.textured(
            "stone",
            speckle(256, [150, 150, 140, 255], [215, 210, 200, 255], 32),
            false,
        ),
        floor: s.textured(
            "floor",
            grain(256, 4, [120, 80, 45, 255], [200, 160, 110, 255], 33),
            false,
        ),
        plaster: s.textured(
            "posters",
            glyphs(256, [230, 225, 210, 255], [40, 70, 150, 255], 34),
            false,
        ),
        roof: s.textured(
            "roof tiles",
            checks(256, 32, [110, 40, 30, 255], [70, 70, 75, 255]),
            false,
        ),
    }
}

/// One wall of [`building`] in its frame `frame` (x along the wall, y up from the ground,
/// +z outside), `length × 9` and `thickness` thick, three floors of `windows` openings each.
fn facade(
    s: &mut SceneBuilder,
    name: &str,
    [length, thickness]: [f32; 2],
    windows: u32,
    frame: Affine3A,
    looks: &BuildingLooks,
) {
    let density = 1.0;
    let (width, half_t) = (1.2f32, thickness / 2.0);
    let centres: Vec<f32> = (0..windows)
        .map(|k| -length / 2.0 + length * (k as f32 + 0.5) / windows as f32)
        .collect();
    for floor in 0..3 {
        let y0 = 3.0 * floor as f32;
        let mut add = |part: &str, half: Vec3, centre: Vec3, material: u32| {
            let piece = block(half, density, 1.0);
            let place = frame * to(centre);
            s.add(format!("{name} {part} {floor}"), &piece, place, material);
        };
        let band = |h: f32| Vec3::new(length / 2.0, h, half_t);
        add("lower band", band(0.5), Vec3::Y * (y0 + 0.5), looks.brick);
        add("upper band", band(0.3), Vec3::Y * (y0 + 2.7), looks.brick);
        let mut edges = vec![-length / 2.0];
        for &c in &centres {
            edges.extend([c - width / 2.0, c + width / 2.0]);
        }
        edges.push(length / 2.0);
        for (k, pier) in edges.chunks(2).enumerate() {
            let half = Vec3::new((pier[1] - pier[0]) / 2.0, 0.7, half_t);
            let centre = Vec3::new((pier[0] + pier[1]) / 2.0, y0 + 1.7, 0.0);
            add(&format!("pier {k}"), half, centre, looks.brick);
        }
        for (k, &c) in centres.iter().enumerate() {
            let half = Vec3::new(0.7, 0.04, 0.12);
            let centre = Vec3::new(c, y0 + 0.98, half_t + 0.06);
            add(&format!("sill {k}"), half, centre, looks.stone);
        }
    }
}

/// Props on a ground slab 12 × 12 (concrete), as a glTF scene instancing three meshes: an
/// 8 × 8 grid whose cell (i, j) holds a crate (glyph labels) where (i + 2j) mod 3 is 0, a
/// bulging barrel (hoop stripes) where it is 1, a traffic cone (hazard stripes) where it is 2, each
/// turned about y and scaled by 0.85 to 1.15 by the cell's hash, and on each crate of an even
/// row j a smaller crate turned on top of it: 22 + 11 crates, 21 barrels, 21 cones and the
/// ground, 76 parts, 4 materials, 25 260 triangles. Every instance of a mesh is its vertices
/// moved by a similarity.
pub fn props() -> Asset {
    let mut s = SceneBuilder::new();
    let concrete = s.textured(
        "concrete",
        speckle(256, [120, 120, 115, 255], [190, 188, 180, 255], 41),
        false,
    );
    let label = s.textured(
        "crate labels",
        glyphs(256, [200, 160, 100, 255], [40, 20, 10, 255], 42),
        false,
    );
    let hoops = s.textured(
        "barrel hoops",
        stripes(256, 32, &[[30, 90, 50, 255], [150, 150, 160, 255]]),
        false,
    );
    let hazard = s.textured(
        "cone stripes",
        stripes(256, 40, &[[240, 90, 20, 255], [245, 245, 245, 255]]),
        false,
    );
    let ground = block(Vec3::new(6.0, 0.05, 6.0), 1.0, 0.5);
    s.add("ground".into(), &ground, to(Vec3::Y * -0.05), concrete);
    let crate_mesh = block(Vec3::splat(0.4), 1.0, 1.25);
    let barrel = lathe(
        &profile(16, |t| [0.3 + 0.06 * (PI * t).sin(), 0.9 * (t - 0.5)]),
        32,
        1.0,
    );
    let cone = frustum([0.3, 0.04, 0.7], 32, 1.0);
    let (mut crates, mut barrels, mut cones) = (0, 0, 0);
    for (i, j) in (0..8u32).flat_map(|j| (0..8u32).map(move |i| (i, j))) {
        let centre = Vec3::new(-4.9 + 1.4 * i as f32, 0.0, -4.9 + 1.4 * j as f32);
        let yaw = Quat::from_rotation_y(TAU * unit(i, j, 43));
        let scale = 0.85 + 0.3 * unit(i, j, 44);
        match (i + 2 * j) % 3 {
            0 => {
                let place = at(centre + Vec3::Y * (0.4 * scale), yaw, Vec3::splat(scale));
                s.add(format!("crate {crates}"), &crate_mesh, place, label);
                crates += 1;
                if j % 2 == 0 {
                    let top = Quat::from_rotation_y(0.6) * yaw;
                    let y = 0.8 * scale + 0.4 * 0.7 * scale;
                    let place = at(centre + Vec3::Y * y, top, Vec3::splat(0.7 * scale));
                    s.add(format!("crate {crates}"), &crate_mesh, place, label);
                    crates += 1;
                }
            }
            1 => {
                let place = at(centre + Vec3::Y * (0.45 * scale), yaw, Vec3::splat(scale));
                s.add(format!("barrel {barrels}"), &barrel, place, hoops);
                barrels += 1;
            }
            _ => {
                let place = at(centre + Vec3::Y * (0.35 * scale), yaw, Vec3::splat(scale));
                s.add(format!("cone {cones}"), &cone, place, hazard);
                cones += 1;
            }
        }
    }
    s.finish()
}
