//! MPPphys plain-text particle files (002 §2.1 and Appendix A).
//!
//! One record per line, `#` or `//` start a comment:
//!
//! | keyword | fields | meaning |
//! |---|---|---|
//! | `pos`  | ID x y z m c r [R G B] | position, mass, charge, radius, colour |
//! | `vel`  | ID vx vy vz | initial velocity (default 0) |
//! | `vfix` | ID fx fy fz | 1 = free, 0 = fixed, per axis |
//! | `dis`  | ID dx dy dz | displacement applied after spring rest lengths are taken |
//! | `s`    | ID D c [R G B] | spring type: stiffness D, damping c (002 Eq. 4) |
//! | `sl`   | i j type [l] | spring between particles i and j; rest length l (default: initial distance) |
//! | `k2`   | value | gravitational constant k² = GM (002 Eq. 2) |
//! | `eps`  | value | softening length ε (002 Eq. 2; a mote extension) |
//! | `grav` | gx gy gz | uniform gravitational acceleration |
//! | `damp` | value | global damping coefficient: force −damp·v on every particle |
//! | `dt`   | value | time step |
//!
//! Particle IDs must run consecutively from 0 in the order of the `pos` lines.

use std::path::Path;

use crate::{IoError, ParseError};

/// One particle of a particle file.
#[derive(Debug, Clone, PartialEq)]
pub struct PlistParticle {
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    pub mass: f64,
    pub charge: f64,
    pub radius: f64,
    pub color: [f64; 3],
    /// Per axis: true where the particle may move (`vfix` 1), false where fixed.
    pub free: [bool; 3],
    /// `dis` displacement, applied after spring rest lengths are taken.
    pub displacement: [f64; 3],
}

/// A spring type (`s` line).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringType {
    pub id: usize,
    pub stiffness: f64,
    pub damping: f64,
    pub color: [f64; 3],
}

/// A spring link (`sl` line).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringLink {
    pub i: usize,
    pub j: usize,
    pub kind: usize,
    pub rest_length: Option<f64>,
}

/// The whole file as plain data.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParticleFile {
    pub particles: Vec<PlistParticle>,
    pub spring_types: Vec<SpringType>,
    pub springs: Vec<SpringLink>,
    pub k2: Option<f64>,
    pub softening: Option<f64>,
    pub gravity: Option<[f64; 3]>,
    pub damping: Option<f64>,
    pub dt: Option<f64>,
}

/// Reads a particle file from disk.
pub fn read(path: &Path) -> Result<ParticleFile, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::os(path, e))?;
    Ok(parse(&text, &path.display().to_string())?)
}

struct Line<'a> {
    file: &'a str,
    number: usize,
    keyword: &'a str,
    fields: Vec<&'a str>,
}

impl Line<'_> {
    fn err(&self, message: impl Into<String>) -> ParseError {
        ParseError::new(self.file, self.number, message)
    }

    fn expect_fields(&self, min: usize, max: usize, form: &str) -> Result<(), ParseError> {
        let n = self.fields.len();
        if n < min || n > max {
            return Err(self.err(format!(
                "'{}' takes {form}, found {n} value{}",
                self.keyword,
                if n == 1 { "" } else { "s" }
            )));
        }
        Ok(())
    }

    fn number(&self, k: usize, what: &str) -> Result<f64, ParseError> {
        let s = self.fields[k];
        let v: f64 = s.parse().map_err(|_| {
            self.err(format!(
                "{what} of '{}' must be a number, found '{s}'",
                self.keyword
            ))
        })?;
        if !v.is_finite() {
            return Err(self.err(format!(
                "{what} of '{}' must be finite, found '{s}'",
                self.keyword
            )));
        }
        Ok(v)
    }

    fn index(&self, k: usize, what: &str) -> Result<usize, ParseError> {
        let s = self.fields[k];
        s.parse().map_err(|_| {
            self.err(format!(
                "{what} of '{}' must be a non-negative integer, found '{s}'",
                self.keyword
            ))
        })
    }

    fn vec3(&self, k: usize, what: &str) -> Result<[f64; 3], ParseError> {
        Ok([
            self.number(k, what)?,
            self.number(k + 1, what)?,
            self.number(k + 2, what)?,
        ])
    }
}

/// Parses the text of a particle file; `file` names it in error messages.
pub fn parse(text: &str, file: &str) -> Result<ParticleFile, ParseError> {
    let mut pf = ParticleFile::default();
    // Records that refer to particles are applied after all `pos` lines are
    // known, so that the file may list them in any order.
    let mut deferred: Vec<Line> = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("");
        let content = content.split("//").next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let mut words = content.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let line = Line {
            file,
            number: k + 1,
            keyword,
            fields: words.collect(),
        };
        match keyword {
            "pos" => {
                line.expect_fields(7, 10, "ID x y z m c r [R G B]")?;
                let id = line.index(0, "the ID")?;
                if id != pf.particles.len() {
                    return Err(line.err(format!(
                        "particle IDs must be consecutive from 0: expected ID {}, found {id}",
                        pf.particles.len()
                    )));
                }
                let mass = line.number(4, "the mass")?;
                if mass <= 0.0 {
                    return Err(line.err(format!("the mass must be positive, found {mass}")));
                }
                let radius = line.number(6, "the radius")?;
                if radius < 0.0 {
                    return Err(line.err(format!("the radius must not be negative, found {radius}")));
                }
                let color = match line.fields.len() {
                    10 => line.vec3(7, "the colour")?,
                    7 => [1.0, 1.0, 1.0],
                    _ => return Err(line.err("the colour needs three values R G B")),
                };
                pf.particles.push(PlistParticle {
                    position: line.vec3(1, "the position")?,
                    velocity: [0.0; 3],
                    mass,
                    charge: line.number(5, "the charge")?,
                    radius,
                    color,
                    free: [true; 3],
                    displacement: [0.0; 3],
                });
            }
            "vel" | "vfix" | "dis" | "sl" => deferred.push(line),
            "s" => {
                line.expect_fields(3, 6, "ID D c [R G B]")?;
                let id = line.index(0, "the ID")?;
                if pf.spring_types.iter().any(|s| s.id == id) {
                    return Err(line.err(format!("spring type {id} is defined twice")));
                }
                let stiffness = line.number(1, "the stiffness D")?;
                let damping = line.number(2, "the damping c")?;
                if stiffness < 0.0 || damping < 0.0 {
                    return Err(line.err("stiffness D and damping c must not be negative"));
                }
                let color = if line.fields.len() == 6 {
                    line.vec3(3, "the colour")?
                } else {
                    [0.4, 0.4, 1.0]
                };
                pf.spring_types.push(SpringType {
                    id,
                    stiffness,
                    damping,
                    color,
                });
            }
            "k2" | "eps" | "damp" | "dt" => {
                line.expect_fields(1, 1, "one value")?;
                let v = line.number(0, "the value")?;
                let slot = match keyword {
                    "k2" => &mut pf.k2,
                    "eps" => &mut pf.softening,
                    "damp" => &mut pf.damping,
                    _ => &mut pf.dt,
                };
                if keyword == "dt" && v <= 0.0 {
                    return Err(line.err(format!("the time step must be positive, found {v}")));
                }
                if keyword != "k2" && keyword != "dt" && v < 0.0 {
                    return Err(line.err(format!("'{keyword}' must not be negative, found {v}")));
                }
                *slot = Some(v);
            }
            "grav" => {
                line.expect_fields(3, 3, "three values gx gy gz")?;
                pf.gravity = Some(line.vec3(0, "the acceleration")?);
            }
            other => {
                return Err(line.err(format!(
                    "unknown keyword '{other}' (expected pos, vel, vfix, dis, s, sl, k2, eps, grav, damp or dt)"
                )))
            }
        }
    }
    let n = pf.particles.len();
    for line in deferred {
        match line.keyword {
            "vel" | "vfix" | "dis" => {
                line.expect_fields(4, 4, "ID and three values")?;
                let id = line.index(0, "the ID")?;
                if id >= n {
                    return Err(line.err(format!(
                        "particle {id} has no 'pos' line (IDs 0..{} exist)",
                        n.saturating_sub(1)
                    )));
                }
                let p = &mut pf.particles[id];
                match line.keyword {
                    "vel" => p.velocity = line.vec3(1, "the velocity")?,
                    "dis" => p.displacement = line.vec3(1, "the displacement")?,
                    _ => {
                        for d in 0..3 {
                            p.free[d] = match line.fields[d + 1] {
                                "1" => true,
                                "0" => false,
                                s => {
                                    return Err(line.err(format!(
                                        "vfix flags are 1 (free) or 0 (fixed), found '{s}'"
                                    )))
                                }
                            };
                        }
                    }
                }
            }
            _ => {
                line.expect_fields(3, 4, "i j type [rest length]")?;
                let i = line.index(0, "the first particle")?;
                let j = line.index(1, "the second particle")?;
                let kind = line.index(2, "the spring type")?;
                for id in [i, j] {
                    if id >= n {
                        return Err(line.err(format!("particle {id} has no 'pos' line")));
                    }
                }
                if i == j {
                    return Err(line.err(format!(
                        "a spring joins two different particles, found {i} twice"
                    )));
                }
                if !pf.spring_types.iter().any(|s| s.id == kind) {
                    return Err(line.err(format!(
                        "spring type {kind} is not defined (define it with 's {kind} D c')"
                    )));
                }
                let rest_length = if line.fields.len() == 4 {
                    let l = line.number(3, "the rest length")?;
                    if l < 0.0 {
                        return Err(line.err("the rest length must not be negative"));
                    }
                    Some(l)
                } else {
                    None
                };
                pf.springs.push(SpringLink {
                    i,
                    j,
                    kind,
                    rest_length,
                });
            }
        }
    }
    if pf.particles.is_empty() {
        return Err(ParseError::new(
            file,
            0,
            "no particles: the file has no 'pos' line",
        ));
    }
    Ok(pf)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SUN_EARTH: &str = "\
# filename: data.plist
#---- ID x y z m c r color (rgb)
pos 0 0.0 0.0 0.0 1.0 0.0 0.1 1.0 1.0 0.0
pos 1 1.0 0.0 0.0 3e-6 0.0 0.03 0.3 0.3 1.0
vel 0 0.0 0.0 0.0
vel 1 0.0 0.0172 0.0
vfix 0 1 1 0
vfix 1 1 1 0
k2 2.9584e-4
dt 0.03
";

    #[test]
    fn reads_the_seed_example() {
        let pf = parse(SUN_EARTH, "data.plist").unwrap();
        assert_eq!(pf.particles.len(), 2);
        assert_eq!(pf.particles[1].velocity, [0.0, 0.0172, 0.0]);
        assert_eq!(pf.particles[0].free, [true, true, false]);
        assert_eq!(pf.k2, Some(2.9584e-4));
        assert_eq!(pf.dt, Some(0.03));
        assert_eq!(pf.particles[1].mass, 3e-6);
    }

    fn error_of(text: &str) -> String {
        parse(text, "f.plist").unwrap_err().to_string()
    }

    #[test]
    fn bad_lines_are_named() {
        assert!(error_of("pos 0 0 0 0 1 0 0\npos 2 0 0 0 1 0 0\n")
            .starts_with("f.plist:2: particle IDs must be consecutive"));
        assert!(error_of("pos 0 0 0 zero 1 0 0\n")
            .starts_with("f.plist:1: the position of 'pos' must be a number"));
        assert!(error_of("pos 0 0 0 0 1 0 0\nvel 3 1 0 0\n")
            .starts_with("f.plist:2: particle 3 has no 'pos' line"));
        assert!(error_of("pos 0 0 0 0 1 0 0\nvfix 0 1 2 1\n").starts_with("f.plist:2: vfix flags"));
        assert!(error_of("pos 0 0 0 0 1 0 0\npos 1 1 0 0 1 0 0\nsl 0 1 4\n")
            .starts_with("f.plist:3: spring type 4 is not defined"));
        assert!(error_of("pos 0 0 0 0 1 0 0\nwobble 3\n")
            .starts_with("f.plist:2: unknown keyword 'wobble'"));
        assert!(error_of("pos 0 0 0 0 1 0 0\ndt -1\n")
            .starts_with("f.plist:2: the time step must be positive"));
        assert!(
            error_of("pos 0 0 0 0 -1 0 0\n").starts_with("f.plist:1: the mass must be positive")
        );
        assert!(error_of("# nothing\n").starts_with("f.plist: no particles"));
        assert!(error_of("pos 0 0 0 0 1 0 0 1 1\n")
            .starts_with("f.plist:1: the colour needs three values"));
        assert!(error_of("pos 0 0 0\n").starts_with("f.plist:1: 'pos' takes ID x y z m c r"));
    }

    #[test]
    fn springs_and_comments() {
        let pf = parse(
            "pos 0 0 0 0 1 0 0 // a comment\n\npos 1 1 0 0 1 0 0\ns 0 50.0 0.003 0.4 0.4 1.0\nsl 0 1 0\nsl 1 0 0 2.5\ngrav 0 0 -9.81\ndamp 0.1\ndis 1 0 0 0.1\n",
            "f",
        )
        .unwrap();
        assert_eq!(pf.springs.len(), 2);
        assert_eq!(pf.springs[1].rest_length, Some(2.5));
        assert_eq!(pf.gravity, Some([0.0, 0.0, -9.81]));
        assert_eq!(pf.damping, Some(0.1));
        assert_eq!(pf.particles[1].displacement, [0.0, 0.0, 0.1]);
    }
}
