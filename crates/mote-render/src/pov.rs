//! The same scene, camera and light as a POV-Ray 3.7 scene file, so that both
//! programs can render the identical picture (for comparisons, and for users who
//! want POV-Ray's extras).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::camera::Camera;
use crate::render::RenderOptions;
use crate::scene::Scene;
use crate::RenderError;

/// Writes `scene` seen by `camera` and lit as in `opts` to a `.pov` file.
/// Render it with `povray +I file.pov +O out.png +W<w> +H<h> -D`.
/// Spheres only (indicator-function bodies have no POV-Ray counterpart here);
/// the box is drawn as thin cylinders.
pub fn write_pov(
    path: &Path,
    scene: &Scene,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<(), RenderError> {
    let file = File::create(path).map_err(|e| RenderError::io(path, e))?;
    let mut out = BufWriter::new(file);
    write_to(&mut out, scene, camera, opts)
        .and_then(|_| out.flush())
        .map_err(|e| RenderError::io(path, e))
}

fn v(p: glam::Vec3) -> String {
    // POV-Ray is left-handed with y up; keep mote's right-handed coordinates by
    // mirroring x in the camera (`right` negative) and using `sky` for up.
    format!("<{}, {}, {}>", p.x, p.y, p.z)
}

fn write_to(
    out: &mut impl Write,
    scene: &Scene,
    cam: &Camera,
    opts: &RenderOptions,
) -> std::io::Result<()> {
    let (r, u, f) = cam.basis();
    let aspect = cam.width as f32 / cam.height as f32;
    let th = (cam.fov_deg.to_radians() * 0.5).tan();
    writeln!(
        out,
        "// written by mote-render: {} spheres",
        scene.spheres.len()
    )?;
    writeln!(out, "#version 3.7;")?;
    writeln!(
        out,
        "global_settings {{ assumed_gamma 1.0 ambient_light rgb <1,1,1> }}"
    )?;
    let bg = opts.background;
    writeln!(
        out,
        "background {{ color rgb <{}, {}, {}> }}",
        bg[0], bg[1], bg[2]
    )?;
    // An explicit camera basis: direction f, right r·(2·aspect·th), up u·(2·th);
    // right-handed by passing the true right vector.
    writeln!(
        out,
        "camera {{ perspective location {} direction {} right {} up {} }}",
        v(cam.eye),
        v(f),
        v(r * (2.0 * aspect * th)),
        v(u * (2.0 * th))
    )?;
    let light = (r * opts.light.x + u * opts.light.y - f * opts.light.z).normalize();
    let size = scene
        .bounds()
        .map(|(lo, hi)| (hi - lo).length())
        .unwrap_or(1.0);
    writeln!(
        out,
        "light_source {{ {} color rgb <1,1,1> parallel point_at {}{} }}",
        v(cam.target + light * (100.0 * size)),
        v(cam.target),
        if opts.shadows { "" } else { " shadowless" }
    )?;
    writeln!(
        out,
        "#declare F = finish {{ ambient {} diffuse {} specular {} roughness {} }}",
        opts.ambient,
        opts.diffuse,
        opts.specular,
        1.0 / opts.shininess
    )?;
    for (s, c) in scene.spheres.iter().zip(&scene.colors) {
        writeln!(
            out,
            "sphere {{ {}, {} pigment {{ rgb <{}, {}, {}> }} finish {{ F }} }}",
            v(s.center),
            s.radius,
            c[0],
            c[1],
            c[2]
        )?;
    }
    if let (true, Some(cell)) = (opts.draw_box, &scene.cell) {
        let w = size * 1e-3;
        let bc = opts.box_color;
        for (a, b) in cell.segments() {
            writeln!(
                out,
                "cylinder {{ {}, {}, {} pigment {{ rgb <{}, {}, {}> }} no_shadow }}",
                v(a),
                v(b),
                w,
                bc[0],
                bc[1],
                bc[2]
            )?;
        }
    }
    Ok(())
}
