//! Pictures that must come out right: geometry (a sphere covers exactly the
//! pixels inside its silhouette), shading and shadows, determinism across thread
//! counts, and golden images (a few spheres, a clump, an anaglyph, an
//! indicator-function body) compared with a tolerance.
//!
//! To regenerate the golden images after an intended change:
//! `MOTE_BLESS=1 cargo test -p mote-render --test render`.

use std::path::PathBuf;

use glam::Vec3;
use mote_render::{Camera, Cell, Image, RenderOptions, Renderer, Scene, Sdf, SdfBody};

fn camera_down_z(d: f32, w: u32, h: u32, fov: f32) -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, d),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_deg: fov,
        width: w,
        height: h,
    }
}

#[test]
fn a_sphere_covers_exactly_its_silhouette() {
    let (w, h) = (120u32, 90u32);
    let d = 10.0f32;
    let mut scene = Scene::new();
    let c = Vec3::new(1.5, -0.5, 0.0);
    let r = 1.25f32;
    scene.add_sphere(c, r, [0.8, 0.2, 0.2]);
    let cam = camera_down_z(d, w, h, 40.0);
    let img = Renderer::new(&scene).render(&cam, &RenderOptions::default());
    let (mut inside, mut checked) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            // The pixel ray is inside the silhouette cone iff its angle to the
            // direction of the centre is below asin(r/|c − eye|).
            let ray = cam.ray(x as f32 + 0.5, y as f32 + 0.5);
            let to_c = (c - cam.eye).normalize();
            let angle = ray.dir.dot(to_c).clamp(-1.0, 1.0).acos();
            let cone = (r / (c - cam.eye).length()).asin();
            if (angle - cone).abs() < 1e-3 {
                continue; // on the rim: rounding decides
            }
            checked += 1;
            let hit = img.depth[(y * w + x) as usize].is_finite();
            assert_eq!(hit, angle < cone, "pixel {x},{y}");
            inside += hit as usize;
            if hit {
                assert_ne!(img.pixel(x, y), [255, 255, 255]);
            } else {
                assert_eq!(img.pixel(x, y), [255, 255, 255]);
            }
        }
    }
    assert!(inside > 200 && checked > 10000, "{inside} of {checked}");
    // Depth at the pixel nearest the centre's projection is the distance to the
    // front of the sphere, |c − eye| − r, up to the pixel's offset.
    let (px, py, _) = cam.project(c).unwrap();
    let t = img.depth[(py as u32 * w + px as u32) as usize];
    assert!((t - ((c - cam.eye).length() - r)).abs() < 0.01, "depth {t}");
}

#[test]
fn lit_side_is_brighter_and_shadows_darken() {
    let (w, h) = (100u32, 100u32);
    let cam = camera_down_z(10.0, w, h, 40.0);
    let mut scene = Scene::new();
    scene.add_sphere(Vec3::ZERO, 2.0, [1.0, 1.0, 1.0]);
    // Light from the right (camera coordinates).
    let opts = RenderOptions {
        light: Vec3::new(1.0, 0.0, 0.0),
        specular: 0.0,
        ..RenderOptions::default()
    };
    let img = Renderer::new(&scene).render(&cam, &opts);
    let right = img.pixel(72, 50)[0];
    let left = img.pixel(28, 50)[0];
    assert!(right > left + 100, "right {right}, left {left}");
    // Ambient only on the dark side: 0.25 of white.
    assert!((left as i32 - 64).abs() <= 1, "left {left}");
    // A small sphere between the big one and the light shadows its right side.
    scene.add_sphere(Vec3::new(4.0, 0.0, 0.5), 0.6, [1.0, 1.0, 1.0]);
    let plain = Renderer::new(&scene).render(&cam, &opts);
    let shadowed = Renderer::new(&scene).render(
        &cam,
        &RenderOptions {
            shadows: true,
            ..opts.clone()
        },
    );
    // The point of the big sphere facing the light straight on, projected: (2, 0, 0)
    // seen from z = 10 lies right of centre.
    let (px, py, _) = cam.project(Vec3::new(1.98, 0.0, 0.2)).unwrap();
    let (px, py) = (px as u32, py as u32);
    let a = plain.pixel(px, py)[0];
    let b = shadowed.pixel(px, py)[0];
    assert!(a > 150 && b < 80, "unshadowed {a}, shadowed {b}");
}

fn many_spheres(n: usize) -> Scene {
    let mut st = 99u64;
    let mut rnd = move || {
        st = st
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((st >> 40) as f32) / (1u64 << 24) as f32
    };
    let mut scene = Scene::new();
    for _ in 0..n {
        let c = Vec3::new(rnd(), rnd(), rnd()) * 10.0;
        scene.add_sphere(c, 0.2 + 0.3 * rnd(), [rnd(), rnd(), rnd()]);
    }
    scene.cell = Some(Cell {
        origin: Vec3::ZERO,
        edges: [Vec3::X * 10.0, Vec3::Y * 10.0, Vec3::Z * 10.0],
    });
    scene
}

#[test]
fn pictures_do_not_depend_on_the_thread_count() {
    let scene = many_spheres(2000);
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, mote_render::camera::DEFAULT_VIEW, 35.0, 160, 120);
    let opts = RenderOptions {
        shadows: true,
        ao_samples: 4,
        ..RenderOptions::default()
    };
    let renderer = Renderer::new(&scene);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| renderer.render(&cam, &opts));
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap()
        .install(|| renderer.render(&cam, &opts));
    assert_eq!(one.rgb, three.rgb);
    // Something was drawn: many distinct colours.
    let distinct: std::collections::HashSet<_> = one.rgb.chunks(3).collect();
    assert!(distinct.len() > 500);
}

fn golden(name: &str, img: &Image) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("{name}.png"));
    if std::env::var_os("MOTE_BLESS").is_some() || !path.exists() {
        img.write_png(&path).unwrap();
        eprintln!("wrote golden image {}", path.display());
        if std::env::var_os("MOTE_BLESS").is_none() {
            panic!("golden image {name} was missing; written now, check it and rerun");
        }
        return;
    }
    let want = Image::read_png(&path).unwrap();
    let (mean, frac) = img.difference(&want, 24).expect("same size");
    // Tolerance: rounding differences across CPUs and compilers change a few
    // pixels on silhouettes by one grey level; real changes move whole regions.
    assert!(
        mean < 0.5 && frac < 0.002,
        "{name}: mean difference {mean:.3}, {:.3} % pixels differ by > 24",
        100.0 * frac
    );
}

#[test]
fn golden_few_spheres() {
    let mut scene = Scene::new();
    scene.add_sphere(Vec3::new(0.0, 0.0, 0.0), 1.0, [0.9, 0.3, 0.2]);
    scene.add_sphere(Vec3::new(2.2, 0.3, 0.0), 0.7, [0.2, 0.5, 0.9]);
    scene.add_sphere(Vec3::new(-1.0, 2.0, -0.5), 0.5, [0.3, 0.8, 0.3]);
    scene.cell = Some(Cell {
        origin: Vec3::new(-1.5, -1.5, -1.5),
        edges: [Vec3::X * 4.5, Vec3::Y * 4.5, Vec3::Z * 3.0],
    });
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, mote_render::camera::DEFAULT_VIEW, 35.0, 160, 120);
    let opts = RenderOptions {
        shadows: true,
        ..RenderOptions::default()
    };
    golden("few_spheres", &Renderer::new(&scene).render(&cam, &opts));
}

fn clump_scene() -> Scene {
    let mut scene = Scene::new();
    // A rigid clump: three overlapping spheres in a bent row (sharp creases
    // where they meet) and a second, separate clump.
    scene.add_clump(
        &[
            (Vec3::new(-1.0, 0.0, 0.0), 0.8),
            (Vec3::new(0.0, 0.0, 0.3), 0.8),
            (Vec3::new(0.9, 0.5, 0.3), 0.6),
        ],
        [0.85, 0.55, 0.15],
    );
    scene.add_clump(
        &[
            (Vec3::new(0.5, -1.8, 0.0), 0.5),
            (Vec3::new(1.2, -1.8, 0.0), 0.5),
        ],
        [0.25, 0.45, 0.85],
    );
    scene
}

#[test]
fn golden_clump() {
    let scene = clump_scene();
    assert_eq!(scene.body, vec![0, 0, 0, 1, 1]);
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, Vec3::new(-0.3, 0.4, -1.0), 35.0, 160, 120);
    let opts = RenderOptions {
        shadows: true,
        ao_samples: 8,
        ..RenderOptions::default()
    };
    golden("clump", &Renderer::new(&scene).render(&cam, &opts));
}

#[test]
fn golden_anaglyph() {
    let scene = clump_scene();
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, Vec3::new(-0.3, 0.4, -1.0), 35.0, 160, 120);
    let opts = RenderOptions {
        lattice: Some(0.25),
        ..RenderOptions::default()
    };
    let r = Renderer::new(&scene);
    let img = r.render_anaglyph(&cam, &opts, None);
    // Red and cyan halves differ where the eyes see different things: at the
    // silhouettes. Background is white in both.
    assert_eq!(img.pixel(0, 0), [255, 255, 255]);
    let differing = img.rgb.chunks(3).filter(|p| p[0] != p[1]).count();
    assert!(differing > 200, "only {differing} pixels show parallax");
    assert!(
        img.rgb.chunks(3).all(|p| p[1] == p[2]),
        "cyan = green + blue"
    );
    golden("anaglyph", &img);
}

#[test]
fn golden_indicator_function_body() {
    // A cube with a ball cut out of a corner, next to a lens (intersection of
    // two balls): sharp edges everywhere.
    let mut scene = Scene::new();
    scene.sdf_bodies.push(SdfBody {
        shape: Sdf::Intersection(vec![
            Sdf::Cuboid {
                center: Vec3::ZERO,
                half: Vec3::splat(1.0),
            },
            Sdf::Complement(Box::new(Sdf::Sphere {
                center: Vec3::new(1.0, -1.0, 1.0),
                radius: 1.1,
            })),
        ]),
        color: [0.7, 0.7, 0.75],
    });
    scene.sdf_bodies.push(SdfBody {
        shape: Sdf::Intersection(vec![
            Sdf::Sphere {
                center: Vec3::new(2.6, 0.0, 0.0),
                radius: 1.0,
            },
            Sdf::Sphere {
                center: Vec3::new(3.4, 0.0, 0.0),
                radius: 1.0,
            },
        ]),
        color: [0.9, 0.4, 0.3],
    });
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, mote_render::camera::DEFAULT_VIEW, 35.0, 160, 120);
    let opts = RenderOptions {
        shadows: true,
        ..RenderOptions::default()
    };
    let img = Renderer::new(&scene).render(&cam, &opts);
    let covered = img.depth.iter().filter(|d| d.is_finite()).count();
    assert!(covered > 2000, "{covered} pixels covered");
    golden("sdf_bodies", &img);
}

#[test]
fn periodic_images_fill_the_box() {
    let mut scene = Scene::new();
    scene.add_sphere(Vec3::new(0.2, 5.0, 0.1), 0.5, [1.0, 0.0, 0.0]);
    scene.add_sphere(Vec3::new(5.0, 5.0, 5.0), 0.5, [0.0, 1.0, 0.0]);
    scene.cell = Some(Cell {
        origin: Vec3::ZERO,
        edges: [Vec3::X * 10.0, Vec3::Y * 10.0, Vec3::Z * 10.0],
    });
    scene.add_periodic_images([true, true, true]);
    // The first sphere crosses two faces: 3 images; the second none.
    assert_eq!(scene.spheres.len(), 5);
    assert!(scene
        .spheres
        .iter()
        .any(|s| s.center == Vec3::new(10.2, 5.0, 10.1)));
    let mut open = scene.clone();
    open.spheres.truncate(2);
    open.colors.truncate(2);
    open.body.truncate(2);
    open.add_periodic_images([false, true, false]);
    assert_eq!(open.spheres.len(), 2);
}
