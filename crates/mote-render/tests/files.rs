//! Plots, colour bars, frames as scenes and the POV-Ray writer.

use glam::Vec3;
use mote_io::xyz::Frame;
use mote_render::frame::{quantity, scene_from_frame, ColorBy};
use mote_render::plot::{axis_label, Plot, Series};
use mote_render::{Camera, ColorMap, Image, RenderOptions, Renderer};

fn energy_plot(log_y: bool) -> Plot {
    let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.05).collect();
    Plot {
        title: Some("energies".into()),
        x_label: axis_label("time", Some("s")),
        y_label: axis_label("energy", Some("J")),
        series: vec![
            Series {
                name: "kinetic_energy".into(),
                x: t.clone(),
                y: t.iter().map(|t| 1.0 + (3.0 * t).sin().powi(2)).collect(),
            },
            Series {
                name: "potential_energy".into(),
                x: t.clone(),
                // Non-positive values are left out on a log axis.
                y: t.iter().map(|t| (3.0 * t).cos().powi(2) - 0.001).collect(),
            },
        ],
        log_x: false,
        log_y,
        width: 640,
        height: 400,
    }
}

#[test]
fn plots_are_written_as_png_and_svg_with_labels() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("e.svg");
    energy_plot(false).write(&svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    for label in [
        "time [s]",
        "energy [J]",
        "kinetic_energy",
        "potential_energy",
    ] {
        assert!(text.contains(label), "svg lacks {label}");
    }
    let png = dir.path().join("e.png");
    energy_plot(true).write(&png).unwrap();
    let img = Image::read_png(&png).unwrap();
    assert_eq!((img.width, img.height), (640, 400));
    // Text and curves in the series colours are there: the first series'
    // colour appears on many pixels.
    let c = mote_render::colormap::category_color(4).map(|v| (v * 255.0) as u8);
    let n = img
        .rgb
        .chunks(3)
        .filter(|p| p.iter().zip(c).all(|(a, b)| a.abs_diff(b) < 4))
        .count();
    assert!(n > 300, "{n} pixels of the first curve");
    let dark = img.rgb.chunks(3).filter(|p| p[0] < 60 && p[1] < 60).count();
    assert!(dark > 500, "{dark} dark (text and axis) pixels");
    // Unknown format and nothing to plot are errors, not panics.
    assert!(energy_plot(false).write(&dir.path().join("e.jpg")).is_err());
    let mut empty = energy_plot(true);
    for s in &mut empty.series {
        s.y.iter_mut().for_each(|y| *y = -1.0);
    }
    let e = empty.write(&png).unwrap_err().to_string();
    assert!(e.contains("no finite points"), "{e}");
}

fn frame() -> Frame {
    Frame {
        time: 0.0,
        cell: [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 4.0]],
        origin: [0.0; 3],
        pbc: [true; 3],
        species: vec!["A".into(), "B".into(), "A".into()],
        positions: vec![[1.0, 1.0, 1.0], [2.0, 2.0, 2.0], [3.0, 1.0, 2.5]],
        velocities: vec![[3.0, 4.0, 0.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]],
        radii: vec![0.4, 0.5, 0.0],
        ..Default::default()
    }
}

#[test]
fn frames_become_coloured_scenes_with_a_colour_bar() {
    let f = frame();
    assert_eq!(quantity(&f, "speed").unwrap(), vec![5.0, 0.0, 1.0]);
    assert_eq!(quantity(&f, "vx").unwrap(), vec![3.0, 0.0, -1.0]);
    let e = quantity(&f, "charge").unwrap_err().to_string();
    assert!(e.contains("unknown quantity 'charge'"), "{e}");
    // A known quantity the frame has no column for: NaN, and not listed.
    assert!(quantity(&f, "spin").unwrap().iter().all(|w| w.is_nan()));
    assert!(!mote_render::frame::quantities_of(&f).contains(&"spin"));
    let (scene, coloring) = scene_from_frame(
        &f,
        &ColorBy::Quantity("speed".into()),
        ColorMap::Viridis,
        0.3,
    )
    .unwrap();
    assert_eq!(coloring.range, Some((0.0, 5.0)));
    assert_eq!(scene.colors[0], ColorMap::Viridis.at(1.0));
    assert_eq!(scene.colors[1], ColorMap::Viridis.at(0.0));
    // The point particle got the default radius; the box is there.
    assert_eq!(scene.spheres[2].radius, 0.3);
    assert!(scene.cell.is_some());
    let (species, _) = scene_from_frame(&f, &ColorBy::Species, ColorMap::Viridis, 0.3).unwrap();
    assert_eq!(species.colors[0], species.colors[2]);
    assert_ne!(species.colors[0], species.colors[1]);

    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, Vec3::new(-1.0, 1.0, -0.5), 30.0, 480, 270);
    let mut img = Renderer::new(&scene).render(&cam, &RenderOptions::default());
    let before = img.clone();
    mote_render::overlay::color_bar(&mut img, ColorMap::Viridis, 0.0, 5.0, "speed [m/s]").unwrap();
    // The bar's top is viridis' yellow end, in the right part of the picture.
    let top = mote_render::colormap::ColorMap::Viridis
        .at(1.0)
        .map(|v| (v * 255.0).round() as u8);
    let found = (0..img.height).any(|y| {
        (img.width * 3 / 4..img.width).any(|x| {
            let p = img.pixel(x, y);
            p.iter().zip(top).all(|(a, b)| a.abs_diff(b) <= 10) && before.pixel(x, y) != p
        })
    });
    assert!(found, "no colour bar drawn");
}

#[test]
fn pov_ray_scene_has_every_sphere_camera_and_light() {
    let f = frame();
    let (scene, _) = scene_from_frame(&f, &ColorBy::Species, ColorMap::Viridis, 0.3).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::frame(lo, hi, Vec3::new(-1.0, 1.0, -0.5), 30.0, 480, 270);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.pov");
    let opts = RenderOptions {
        shadows: true,
        ..RenderOptions::default()
    };
    mote_render::pov::write_pov(&path, &scene, &cam, &opts).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches("sphere {").count(), 3);
    assert_eq!(text.matches("cylinder {").count(), 12);
    assert!(text.contains("sphere { <1, 1, 1>, 0.4"));
    assert!(text.contains("camera { perspective location"));
    assert!(text.contains("light_source") && !text.contains("shadowless"));
}

#[test]
fn point_particles_get_a_radius_from_their_spacing() {
    // 100 particles on a 10 × 10 square grid of spacing 1 in the plane z = 0:
    // the spread is 9 × 9, the mean spacing 0.9, the radius a third of it.
    let mut f = frame();
    f.positions = (0..100)
        .map(|k| [(k % 10) as f64, (k / 10) as f64, 0.0])
        .collect();
    let r = mote_render::frame::default_radius(&f);
    assert!((r - 0.3).abs() < 1e-12, "{r}");
}

#[test]
fn one_call_picture_of_a_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("end.png");
    mote_render::frame::picture(&frame(), &path, 200, 150).unwrap();
    let img = Image::read_png(&path).unwrap();
    assert_eq!((img.width, img.height), (200, 150));
    // Species A and B in their palette colours are both visible somewhere.
    let lit = |c: [f32; 3]| {
        img.rgb.chunks(3).any(|p| {
            // Some shade of the colour: channels in the same proportion.
            let s = p[0] as f32 + p[1] as f32 + p[2] as f32;
            let t = (c[0] + c[1] + c[2]) * 255.0;
            s > 30.0 && (0..3).all(|k| (p[k] as f32 / s - c[k] * 255.0 / t).abs() < 0.03)
        })
    };
    assert!(lit(mote_render::colormap::category_color(0)));
    assert!(lit(mote_render::colormap::category_color(1)));
    let empty = Frame::default();
    assert!(mote_render::frame::picture(&empty, &path, 10, 10).is_err());
}
