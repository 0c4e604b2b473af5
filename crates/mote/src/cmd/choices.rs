//! The values of the enumerated options, for clap to check and for
//! `--help` to list: each is the set the library that reads the option
//! accepts (the tests below hold them to it), with the other spellings that
//! library takes as hidden aliases.

use clap::builder::{PossibleValue, PossibleValuesParser};

fn parser(values: impl IntoIterator<Item = PossibleValue>) -> PossibleValuesParser {
    PossibleValuesParser::new(values)
}

/// `--solver`: the integrators (MPPphys' EU, SE, RK4, LF and the other
/// names [`mote_md::Integrator::from_name`] reads, any case).
pub fn solver() -> PossibleValuesParser {
    parser([
        PossibleValue::new("leapfrog").aliases(["lf", "LF", "leap-frog", "velocity-verlet", "kdk"]),
        PossibleValue::new("rk4").aliases(["RK4", "runge-kutta"]),
        PossibleValue::new("symplectic-euler").aliases([
            "symplectic_euler",
            "semi-implicit-euler",
            "semi_implicit_euler",
        ]),
        PossibleValue::new("euler").aliases(["explicit-euler", "explicit_euler"]),
    ])
}

/// `--system`: the model of an MPPphys particle file.
pub fn plist_system() -> PossibleValuesParser {
    parser([
        PossibleValue::new("nbody").help("DirectNbody: gravity between all pairs"),
        PossibleValue::new("springs").help("MassSpring: the file's springs"),
    ])
}

/// `--trajectory-format`: the trajectory writers ([`mote_io::trajectory::Format`]).
pub fn trajectory_format() -> PossibleValuesParser {
    parser([
        PossibleValue::new("xyz").help("extended XYZ (ASE, OVITO)"),
        PossibleValue::new("dump").help("LAMMPS dump"),
        PossibleValue::new("gsd").help("HOOMD-blue GSD"),
        PossibleValue::new("vtk").help("VTK polydata, one .vtp per frame in a .pvd"),
    ])
}

/// `mote pack --method`.
pub fn pack_method() -> PossibleValuesParser {
    parser([
        PossibleValue::new("hard").help("grow hard spheres (Lubachevsky–Stillinger, event-driven)"),
        PossibleValue::new("soft").help("the SP method: Hertzian spheres under a barostat"),
    ])
}

/// `mote render --colormap`.
pub fn colormap() -> PossibleValuesParser {
    parser(["viridis", "coolwarm", "heat"].map(PossibleValue::new))
}

/// `mote render --color-by`: `species` or a per-particle quantity.
pub fn color_by() -> PossibleValuesParser {
    parser(
        std::iter::once("species")
            .chain(mote_render::frame::QUANTITIES.iter().copied())
            .map(PossibleValue::new),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::builder::TypedValueParser;

    /// Every value and alias clap lets through.
    fn accepted(p: &PossibleValuesParser) -> Vec<String> {
        p.possible_values()
            .into_iter()
            .flatten()
            .flat_map(|v| {
                v.get_name_and_aliases()
                    .map(String::from)
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    #[test]
    fn every_listed_value_is_one_its_reader_takes() {
        for v in accepted(&solver()) {
            assert!(mote_md::Integrator::from_name(&v).is_some(), "--solver {v}");
        }
        for v in accepted(&trajectory_format()) {
            assert!(
                mote_io::trajectory::Format::named(&v).is_some(),
                "--trajectory-format {v}"
            );
        }
        for v in accepted(&colormap()) {
            assert!(mote_render::ColorMap::parse(&v).is_some(), "--colormap {v}");
        }
        assert_eq!(accepted(&plist_system()), ["nbody", "springs"]);
        assert_eq!(accepted(&pack_method()), ["hard", "soft"]);
        assert_eq!(
            accepted(&color_by()).len(),
            mote_render::frame::QUANTITIES.len() + 1
        );
    }

    #[test]
    fn a_value_outside_the_set_is_refused_by_clap() {
        let cmd = clap::Command::new("t");
        let p = solver();
        assert!(p
            .parse_ref(&cmd, None, std::ffi::OsStr::new("verlet"))
            .is_err());
        assert!(p.parse_ref(&cmd, None, std::ffi::OsStr::new("LF")).is_ok());
    }
}
