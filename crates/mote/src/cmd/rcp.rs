//! `mote rcp`: the rod-packing estimate of the random close packing fraction, a drop-in
//! replacement for spherepack1d (seed 003, appendix; Farr & Groot 2009), plus the
//! inverse-design subcommands `mote rcp optimize` and `mote rcp scan`.
//!
//! The classic interface is parsed by hand in the manner of getopt
//! (`hVdlwuvisp:N:f:`), so that `-di`, `-p 3`, `-p3`, `-N 1000` and `-f 7654` work as
//! they do for spherepack1d; `--compat`, `--help` and `--version` are added.

use std::io::{BufRead, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Context};
use clap::Parser;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use mote_rcp::design::{self, Axis, Objective};
use mote_rcp::{
    lognormal_fit, ErfcFlavour, Population, RodPacking, SizeDistribution, DEFAULT_RODS,
    MONODISPERSE_FIT, SPHERE_GAP_FRACTION,
};

/// Exit status of every input error (spherepack1d returns −1 from main).
const ERROR_EXIT: u8 = 255;

/// Rod counts from which a progress bar is shown.
const PROGRESS_FROM: usize = 10_000_000;
/// N rods on the periodic line leave N gaps, 8 bytes each, in the packer.
const BYTES_PER_ROD: f64 = 8.0;

pub fn run(global: &super::GlobalOpts, args: &[String]) -> anyhow::Result<ExitCode> {
    match args.first().map(String::as_str) {
        Some("optimize") | Some("optimise") => optimize(global, &args[1..]),
        Some("scan") => scan(global, &args[1..]),
        _ => {
            let stdin = std::io::stdin();
            let mut input = stdin.lock();
            let stdout = std::io::stdout();
            let mut out = stdout.lock();
            match classic(global, args, &mut input, &mut out) {
                Ok(()) => Ok(ExitCode::SUCCESS),
                Err(Exit::Done) => Ok(ExitCode::SUCCESS),
                Err(Exit::Error(msg)) => {
                    out.flush().ok();
                    tell!("{msg}");
                    Ok(ExitCode::from(ERROR_EXIT))
                }
                Err(Exit::Io(e)) => Err(e.into()),
            }
        }
    }
}

/// How the classic interface stops early.
enum Exit {
    /// `-h` or `-V`: printed, nothing else to do.
    Done,
    /// An input error: the message for stderr.
    Error(String),
    Io(std::io::Error),
}

impl From<std::io::Error> for Exit {
    fn from(e: std::io::Error) -> Self {
        Exit::Io(e)
    }
}

fn err<T>(msg: impl Into<String>) -> Result<T, Exit> {
    Err(Exit::Error(msg.into()))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// `-d`: diameter, volume.
    Delta,
    /// `-l`: d43, d32, volume.
    LogD32,
    /// `-w`: d43, sigma, volume.
    LogSigma,
}

/// Whitespace-separated items from standard input with their line numbers,
/// read a line at a time so that the prompts of `-v` work interactively.
/// Bytes that are not UTF-8 become U+FFFD, so such an item is "not a
/// number" with its line, like any other.
struct Items<'a, R: BufRead> {
    input: &'a mut R,
    pending: std::collections::VecDeque<(usize, String)>,
    lines: usize,
}

impl<'a, R: BufRead> Items<'a, R> {
    fn new(input: &'a mut R) -> Self {
        Items {
            input,
            pending: Default::default(),
            lines: 0,
        }
    }

    fn next_item(&mut self) -> Result<Option<(usize, String)>, Exit> {
        while self.pending.is_empty() {
            let mut line = Vec::new();
            if self.input.read_until(b'\n', &mut line)? == 0 {
                return Ok(None);
            }
            self.lines += 1;
            let n = self.lines;
            self.pending.extend(
                String::from_utf8_lossy(&line)
                    .split_whitespace()
                    .map(|w| (n, w.to_string())),
            );
        }
        Ok(self.pending.pop_front())
    }

    fn number(&mut self, what: &str) -> Result<f64, Exit> {
        let Some((line, item)) = self.next_item()? else {
            return err(format!("Error: the input ended early: expected {what}."));
        };
        match item.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => err(format!(
                "Error: standard input:{line}: {what} must be a finite number, got '{item}'."
            )),
            Err(_) => err(format!(
                "Error: standard input:{line}: '{item}' is not a number (expected {what})."
            )),
        }
    }
}

fn int_arg(opt: char, value: &str) -> Result<i64, Exit> {
    value
        .trim()
        .parse::<i64>()
        .or_else(|_| err(format!("Error: -{opt} needs an integer, got '{value}'.")))
}

fn classic<R: BufRead, W: Write>(
    global: &super::GlobalOpts,
    args: &[String],
    input: &mut R,
    out: &mut W,
) -> Result<(), Exit> {
    let mut mode = Mode::Delta;
    let mut n = DEFAULT_RODS;
    let mut p: usize = 1;
    let mut f = SPHERE_GAP_FRACTION;
    let (mut iflag, mut uflag, mut pflag, mut sflag, mut fflag) =
        (false, false, false, false, false);
    let mut verbose = false;
    let mut compat = false;

    let mut k = 0;
    while k < args.len() {
        let arg = &args[k];
        k += 1;
        if arg == "--" {
            if let Some(extra) = args.get(k) {
                return err(format!(
                    "Error: unexpected argument '{extra}': the data are read from standard input."
                ));
            }
            break;
        }
        if let Some(long) = arg.strip_prefix("--") {
            match long {
                "compat" => compat = true,
                "help" => {
                    out.write_all(HELP.as_bytes())?;
                    return Err(Exit::Done);
                }
                "version" => {
                    writeln!(out, "{}", version())?;
                    return Err(Exit::Done);
                }
                _ => return err(format!("Error: unknown option {arg} (see mote rcp -h).")),
            }
            continue;
        }
        let Some(flags) = arg.strip_prefix('-').filter(|s| !s.is_empty()) else {
            return err(format!(
                "Error: unexpected argument '{arg}': the data are read from standard input."
            ));
        };
        let chars: Vec<char> = flags.chars().collect();
        let mut j = 0;
        while j < chars.len() {
            let c = chars[j];
            j += 1;
            match c {
                'h' => {
                    out.write_all(HELP.as_bytes())?;
                    return Err(Exit::Done);
                }
                'V' => {
                    writeln!(out, "{}", version())?;
                    return Err(Exit::Done);
                }
                'v' => {
                    verbose = true;
                    writeln!(out, ">>> Verbose mode <<<")?;
                }
                'd' => mode = Mode::Delta,
                'l' => mode = Mode::LogD32,
                'w' => mode = Mode::LogSigma,
                'u' => uflag = true,
                'i' => iflag = true,
                's' => sflag = true,
                'p' | 'N' | 'f' => {
                    let value: String = if j < chars.len() {
                        let v = chars[j..].iter().collect();
                        j = chars.len();
                        v
                    } else if k < args.len() {
                        k += 1;
                        args[k - 1].clone()
                    } else {
                        return err(format!("Error: -{c} without integer."));
                    };
                    let v = int_arg(c, &value)?;
                    match c {
                        'N' => {
                            if v < 2 {
                                return err("Error: Number of rods needs to be at least 2.");
                            }
                            n = usize::try_from(v).unwrap_or(usize::MAX);
                            if verbose {
                                writeln!(out, "Number of rods is {n}")?;
                            }
                        }
                        'p' => {
                            pflag = true;
                            if v < 1 {
                                return err(
                                    "Error: Number of sphere populations needs to be at least 1.",
                                );
                            }
                            p = usize::try_from(v).unwrap_or(usize::MAX);
                            if verbose {
                                writeln!(out, "Number of data lines is {p}")?;
                            }
                        }
                        _ => {
                            if v < 0 {
                                return err(
                                    "Error: the -f value needs to be non-negative (f = value/10^4; 7654 for spheres).",
                                );
                            }
                            fflag = true;
                            f = 0.0001 * v as f64;
                        }
                    }
                }
                other => {
                    return err(format!("Error: unknown option -{other} (see mote rcp -h)."));
                }
            }
        }
    }

    if iflag && pflag {
        return err("Error: -i option has been chosen, which is not compatible with entering\nthe number of populations in the command line.");
    }
    if sflag {
        if p != 1 {
            return err("Error: -s option requires a single population.");
        }
        if iflag {
            return err("Error: -s option is not compatible with -i option\n(it assumes a single population).");
        }
        if uflag {
            return err("Error: -s option is not compatible with -u option\n(there is no need to specify the volume).");
        }
    }
    if verbose {
        match mode {
            Mode::Delta => writeln!(
                out,
                "The sphere size distribution is a sum of delta functions."
            )?,
            _ => writeln!(
                out,
                "The sphere size distribution is a sum of lognormal distributions."
            )?,
        }
        if uflag {
            writeln!(out, "Data format will be the same for p=1 as for p>1.")?;
        }
        if iflag {
            writeln!(
                out,
                "The number of populations p is read as the first item of standard input."
            )?;
        }
        if fflag {
            writeln!(out, "Value of 'f' parameter is {f:.6}")?;
        }
    }
    let flavour = if compat {
        ErfcFlavour::AbramowitzStegun
    } else {
        ErfcFlavour::Accurate
    };
    let mut items = Items::new(input);
    if iflag {
        if verbose {
            let kind = if mode == Mode::Delta {
                "delta-function"
            } else {
                "lognormal"
            };
            writeln!(
                out,
                "How many {kind} populations does the distribution consist of?"
            )?;
            out.flush()?;
        }
        let Some((line, item)) = items.next_item()? else {
            return err("Error: the input ended early: expected the number of populations.");
        };
        let v: i64 = item.parse().or_else(|_| {
            err(format!(
                "Error: standard input:{line}: expected the number of populations as the first item of the input, found '{item}'."
            ))
        })?;
        if v < 1 {
            return err("Error: Number of sphere populations needs to be at least 1.");
        }
        p = usize::try_from(v).unwrap_or(usize::MAX);
    }
    let single = p == 1 && !uflag;
    let mut pops: Vec<Population> = Vec::new();
    match mode {
        Mode::LogD32 if single => {
            if verbose {
                writeln!(out, "Please input data on the lognormal population, in the format of a\n d43 d32 \npair")?;
                out.flush()?;
            }
            let d43 = items.number("d43")?;
            let d32 = items.number("d32")?;
            if d43 <= 0.0 || d32 <= 0.0 || d32 > d43 {
                return err("Error: must have d43 >= d32 > 0.");
            }
            let sigma = (d43 / d32).ln().max(0.0).sqrt();
            if sflag {
                return print_fit(out, verbose, lognormal_fit(sigma, compat));
            }
            pops.push(Population::lognormal(d43, sigma, 1.0));
        }
        Mode::LogSigma if single => {
            if verbose {
                writeln!(
                    out,
                    "Please input the log width sigma for the lognormal population."
                )?;
                out.flush()?;
            }
            let sigma = items.number("sigma")?;
            if sigma < 0.0 {
                return err("Error: must have sigma >= 0.");
            }
            if sflag {
                return print_fit(out, verbose, lognormal_fit(sigma, compat));
            }
            pops.push(Population::lognormal(1.0, sigma, 1.0));
        }
        Mode::Delta if sflag => return print_fit(out, verbose, MONODISPERSE_FIT),
        Mode::Delta if single => pops.push(Population::monodisperse(1.0, 1.0)),
        Mode::LogD32 | Mode::LogSigma => {
            if verbose {
                let second = if mode == Mode::LogD32 { "d32" } else { "sigma" };
                writeln!(out, "Please input data on the {p} lognormal populations, in the format of\n d43 {second} volume \ntriples")?;
                out.flush()?;
            }
            for i in 1..=p {
                let d43 = items.number(&format!("d43 of population {i}"))?;
                let second = if mode == Mode::LogD32 {
                    items.number(&format!("d32 of population {i}"))?
                } else {
                    items.number(&format!("sigma of population {i}"))?
                };
                let vol = items.number(&format!("the volume of population {i}"))?;
                let sigma = if mode == Mode::LogD32 {
                    if d43 <= 0.0 || second <= 0.0 || second > d43 {
                        return err("Error: need 0 < d32 <= d43.");
                    }
                    (d43 / second).ln().max(0.0).sqrt()
                } else {
                    if second < 0.0 || d43 <= 0.0 {
                        return err("Error: need sigma >= 0 and d43 > 0.");
                    }
                    second
                };
                if vol < 0.0 {
                    return err("Error: need non-negative values for the volume.");
                }
                pops.push(Population::lognormal(d43, sigma, vol));
            }
        }
        Mode::Delta => {
            if verbose {
                writeln!(out, "Please input data on the {p} delta function populations, in the format of\n diameter volume \npairs")?;
                out.flush()?;
            }
            for i in 1..=p {
                let d = items.number(&format!("the diameter of population {i}"))?;
                let vol = items.number(&format!("the volume of population {i}"))?;
                if d <= 0.0 {
                    return err("Error: need strictly positive values for the diameter.");
                }
                if vol < 0.0 {
                    return err("Error: need non-negative values for the volume.");
                }
                pops.push(Population::monodisperse(d, vol));
            }
        }
    }
    if !pops.iter().any(|q| q.volume() > 0.0) {
        return err("Error: One of the volumes must be greater than zero.");
    }
    if verbose {
        writeln!(out, "Getting the number fractions of the populations:")?;
    }
    let dist = SizeDistribution::new(pops).or_else(|e| err(format!("Error: {e}.")))?;
    if verbose {
        writeln!(out, "Constructing and packing the rods:")?;
    }
    if let Err(m) = mote_io::system::check_fits(
        &format!("-N {n}: the rod packing"),
        n as f64 * BYTES_PER_ROD,
    ) {
        return err(format!("Error: {m}."));
    }
    let estimator = RodPacking::default().rods(n).gap_fraction(f).erfc(flavour);
    let bar = if n >= PROGRESS_FROM && !global.quiet {
        let bar = ProgressBar::with_draw_target(Some(n as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {human_pos}/{human_len} rods  ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    // Refused where the rods cannot resolve the distribution (a population
    // with no rod, a width past the last quantile); noted where the third
    // decimal may be off (mote_rcp::resolution).
    let packing = estimator
        .checked_estimate(&dist, |done| bar.set_position(done as u64))
        .or_else(|e| err(format!("Error: {e}.")))?;
    bar.finish_and_clear();
    if let (Some(note), false) = (&packing.note, global.quiet) {
        tell!("{note}");
    }
    if verbose {
        writeln!(out, "\nPredicted maximum packing fraction:")?;
    }
    writeln!(out, "{:.6}", packing.phi)?;
    Ok(())
}

fn print_fit<W: Write>(out: &mut W, verbose: bool, phi: f64) -> Result<(), Exit> {
    if verbose {
        writeln!(out, "\nPredicted maximum packing fraction:")?;
    }
    writeln!(out, "{phi:.6}")?;
    Ok(())
}

fn version() -> String {
    format!(
        "mote rcp {} (rod-packing estimator; drop-in for spherepack1d 1.2)",
        env!("CARGO_PKG_VERSION")
    )
}

const HELP: &str = "\
NAME
    mote rcp - estimate the random close packed volume fraction of a
    distribution of sphere sizes (drop-in replacement for spherepack1d)

SYNOPSIS
    mote rcp [-dhilsuvVw] [-p integer] [-N integer] [-f integer] [--compat]
        [[integer]]
        [real] [real] [real]
        [real] [real] [real]
        ...
    mote rcp optimize --help
    mote rcp scan --help

DESCRIPTION
    The size distribution is read from standard input and the estimated
    random close packed volume fraction is printed with six decimals. The
    estimate is the 1-D rod packing of Farr and Groot, J. Chem. Phys. 131,
    244104 (2009), applied to lognormal mixtures by Farr (2013).

    -d  The size distribution is a sum of monodisperse populations
        (delta functions), each given as: diameter volume.
        This is the default.

    -l  The size distribution is a sum of lognormal populations, each given
        as: d43 d32 volume (volume- and surface-weighted mean diameters,
        occluded volume). With a single population only d43 d32 are read.

    -w  As -l, but each lognormal is given as: d43 sigma volume, where sigma
        is the log-width, exp(sigma^2) = d43/d32. With a single population
        only sigma is read.

    -f  The gap parameter f of the packing, given as an integer that is
        divided by 10^4. The default 7654 (f = 0.7654) is the value for
        spheres.

    -h  Print this help and exit.

    -N  Number of rods (at least 2, no upper limit). Default 16000.
        Runs of 10^7 rods or more show a progress bar on stderr.

    -p  Number of populations (lines of data) to read. Default 1.

    -i  Read the number of populations p as the first item of standard
        input instead of taking it from -p.

    -s  For a single lognormal population, print the analytic fit to the
        rod-packing results (Farr 2013, Eq. 27) instead of packing rods.
        With -d it prints the monodisperse value 0.6435.

    -u  Uniform input: always read full lines (diameter volume for -d;
        three numbers for -l and -w), also when p = 1.

    -v  Verbose: say what is being done and ask for the data.

    -V  Print the version and exit.

    --compat
        Evaluate erfc with the Abramowitz & Stegun 7.1.26 approximation
        used by spherepack1d, reproducing its printed digits. By default
        an accurate erfc (error < 1e-15) is used; for lognormal input the
        two differ by up to ~1e-4 in the result when sigma >= 1.5.

    The occluded volume of a population is the volume its particles would
    displace if submerged; with one material density it can be replaced by
    the mass. Only ratios of volumes matter. Monodisperse populations of
    equal diameter are merged. Input errors are reported on stderr with
    exit status 255.

EXAMPLES
    One lognormal population with d43 = 2.0 and d32 = 0.5:

        printf '2.0 0.5\\n' | mote rcp -l --compat
        0.829998

    Equal masses of two lognormal populations (d43 = 5.0, d32 = 4.0) and
    (d43 = 3.0, d32 = 2.0):

        printf '5.0 4.0 1.0\\n3.0 2.0 1.0\\n' | mote rcp -l -p 2

    Three monodisperse populations, diameters 2.0, 3.0 and 4.0, masses in
    the ratio 1.5:2.5:3.5:

        printf '2.0 1.5\\n3.0 2.5\\n4.0 3.5\\n' | mote rcp -d -p 3

    The same, with the number of populations as the first input item:

        printf '3\\n2.0 1.5\\n3.0 2.5\\n4.0 3.5\\n' | mote rcp -di

    Monodisperse spheres (no input is read):

        mote rcp --compat
        0.643485
";

/// Populations for the design subcommands, in the uniform (`-u`) line format.
#[derive(clap::Args, Debug)]
struct DesignInput {
    /// Monodisperse populations: `diameter volume` per line (the default).
    #[arg(short = 'd', conflicts_with_all = ["lognormal_d32", "lognormal_sigma"])]
    delta: bool,
    /// Lognormal populations: `d43 d32 volume` per line.
    #[arg(short = 'l', conflicts_with = "lognormal_sigma")]
    lognormal_d32: bool,
    /// Lognormal populations: `d43 sigma volume` per line.
    #[arg(short = 'w')]
    lognormal_sigma: bool,
    /// Read the populations from this file instead of standard input.
    #[arg(long, value_name = "FILE")]
    file: Option<PathBuf>,
    /// Number of rods per evaluation.
    #[arg(short = 'N', long = "rods", value_name = "INT", default_value_t = DEFAULT_RODS)]
    rods: usize,
    /// Gap parameter f as an integer divided by 10^4.
    #[arg(short = 'f', value_name = "INT", default_value_t = 7654)]
    f: u32,
    /// Abramowitz & Stegun erfc, as spherepack1d.
    #[arg(long)]
    compat: bool,
}

impl DesignInput {
    fn populations(&self) -> anyhow::Result<Vec<Population>> {
        let (text, name) = match &self.file {
            Some(path) => (
                std::fs::read_to_string(path)
                    .with_context(|| format!("cannot read {}", path.display()))?,
                path.display().to_string(),
            ),
            None => {
                let mut s = String::new();
                std::io::Read::read_to_string(&mut std::io::stdin(), &mut s)?;
                (s, "standard input".to_string())
            }
        };
        let per = if self.lognormal_d32 || self.lognormal_sigma {
            3
        } else {
            2
        };
        let mut pops = Vec::new();
        for (ln, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("");
            let nums: Vec<&str> = line.split_whitespace().collect();
            if nums.is_empty() {
                continue;
            }
            let at = format!("{name}:{}", ln + 1);
            if nums.len() != per {
                bail!(
                    "{at}: expected {per} numbers on the line, found {}",
                    nums.len()
                );
            }
            let v: Vec<f64> = nums
                .iter()
                .map(|s| {
                    s.parse::<f64>()
                        .with_context(|| format!("{at}: '{s}' is not a number"))
                })
                .collect::<anyhow::Result<_>>()?;
            let pop = if self.lognormal_d32 {
                Population::lognormal_d32(v[0], v[1], v[2]).with_context(|| at.clone())?
            } else if self.lognormal_sigma {
                Population::lognormal(v[0], v[1], v[2])
            } else {
                Population::monodisperse(v[0], v[1])
            };
            pops.push(pop);
        }
        if pops.is_empty() {
            bail!("{name}: no populations given (one line of {per} numbers per population)");
        }
        SizeDistribution::new(pops.iter().copied()).with_context(|| name.clone())?;
        Ok(pops)
    }

    fn estimator(&self) -> anyhow::Result<RodPacking> {
        if self.rods < 2 {
            bail!("-N {}: the rod packing needs at least 2 rods", self.rods);
        }
        mote_io::system::check_fits(
            &format!("-N {}: the rod packing", self.rods),
            self.rods as f64 * BYTES_PER_ROD,
        )
        .map_err(anyhow::Error::msg)?;
        Ok(RodPacking::default()
            .rods(self.rods)
            .gap_fraction(f64::from(self.f) * 1e-4)
            .erfc(if self.compat {
                ErfcFlavour::AbramowitzStegun
            } else {
                ErfcFlavour::Accurate
            }))
    }
}

/// `mote rcp optimize`: the volume fractions (and lognormal widths) that maximise φ or
/// reach a target φ (003, §V).
#[derive(Parser, Debug)]
#[command(
    name = "mote rcp optimize",
    about = "Maximise the rod-packing estimate of random close packing, or hit a target, over volume fractions and widths",
    after_help = "Example (tridisperse, size ratios 1:3:9, as in 003 Fig. 6):\n  printf '1 1\\n3 1\\n9 1\\n' | mote rcp optimize -N 4000"
)]
struct OptimizeArgs {
    #[command(flatten)]
    input: DesignInput,
    /// What to vary: `volumes`, `widths` (lognormal σ) or both, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "volumes", value_parser = ["volumes", "widths"])]
    vary: Vec<String>,
    /// Aim at this φ instead of the largest.
    #[arg(long, value_name = "PHI")]
    target: Option<f64>,
    /// At most this many evaluations of φ.
    #[arg(long, default_value_t = 600)]
    max_evals: usize,
}

fn search_from(vary: &[String], max_evals: usize) -> anyhow::Result<design::Search> {
    let mut s = design::Search {
        volumes: false,
        widths: false,
        max_evaluations: max_evals,
        ..Default::default()
    };
    for v in vary {
        match v.as_str() {
            "volumes" | "volume" | "vol" => s.volumes = true,
            "widths" | "width" | "sigma" | "sigmas" => s.widths = true,
            other => bail!("--vary {other}: expected volumes, widths or volumes,widths"),
        }
    }
    Ok(s)
}

fn optimize(global: &super::GlobalOpts, args: &[String]) -> anyhow::Result<ExitCode> {
    let a = match super::parse_words::<OptimizeArgs>("mote rcp optimize", args) {
        Ok(a) => a,
        Err(code) => return Ok(code),
    };
    let pops = a.input.populations()?;
    let est = a.input.estimator()?;
    let search = search_from(&a.vary, a.max_evals)?;
    let objective = match a.target {
        Some(t) if !(0.0..=1.0).contains(&t) => {
            bail!("--target {t}: a packing fraction lies between 0 and 1")
        }
        Some(t) => Objective::Target(t),
        None => Objective::Maximise,
    };
    let started = std::time::Instant::now();
    let opt = design::optimise(&pops, &est, objective, &search)?;
    let total: f64 = opt.populations.iter().map(|q| q.volume()).sum();
    say!("population,d43,sigma,volume_fraction");
    for (k, q) in opt.populations.iter().enumerate() {
        say!(
            "{},{},{:.6},{:.6}",
            k + 1,
            q.d43(),
            q.sigma(),
            q.volume() / total
        );
    }
    say!("phi = {:.6}", opt.phi);
    say!("evaluations = {}", opt.evaluations);
    if !global.quiet {
        tell!(
            "{} evaluations of {} rods in {:.2} s",
            opt.evaluations,
            est.rods,
            started.elapsed().as_secs_f64()
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `mote rcp scan`: φ on a grid of two parameters, as CSV and a PNG heat map.
#[derive(Parser, Debug)]
#[command(
    name = "mote rcp scan",
    about = "Scan the rod-packing estimate over two parameters: CSV and a PNG heat map with a colour bar",
    after_help = "PARAM is volK, dK (diameter or d43) or sigmaK, K the population number from 1.\n\
Example (003 Fig. 6: tridisperse, best composition for each pair of size ratios):\n  \
printf '1 1\\n2 1\\n4 1\\n' | mote rcp scan -N 2000 --x d2=1:5:9 --y d3=1:25:9 --optimize-volumes --csv fig6.csv --png fig6.png"
)]
struct ScanArgs {
    #[command(flatten)]
    input: DesignInput,
    /// x axis as PARAM=START:STOP:COUNT.
    #[arg(long, value_name = "SPEC")]
    x: String,
    /// y axis as PARAM=START:STOP:COUNT.
    #[arg(long, value_name = "SPEC")]
    y: String,
    /// At each point, maximise φ over the volume fractions (003, Fig. 6).
    #[arg(long)]
    optimize_volumes: bool,
    /// Write the grid here as CSV.
    #[arg(long, value_name = "FILE")]
    csv: PathBuf,
    /// Draw the heat map here (PNG).
    #[arg(long, value_name = "FILE")]
    png: Option<PathBuf>,
}

fn scan(global: &super::GlobalOpts, args: &[String]) -> anyhow::Result<ExitCode> {
    let a = match super::parse_words::<ScanArgs>("mote rcp scan", args) {
        Ok(a) => a,
        Err(code) => return Ok(code),
    };
    let x: Axis = a.x.parse().context("--x")?;
    let y: Axis = a.y.parse().context("--y")?;
    let pops = a.input.populations()?;
    let est = a.input.estimator()?;
    let search = design::Search::default();
    let points = x.count.saturating_mul(y.count);
    let bar = if global.quiet {
        ProgressBar::hidden()
    } else {
        let bar = ProgressBar::with_draw_target(Some(points as u64), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {pos}/{len} points  ETA {eta}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    };
    let started = std::time::Instant::now();
    let result = design::scan(
        &pops,
        &est,
        x,
        y,
        a.optimize_volumes.then_some(&search),
        |done| bar.set_position(done as u64),
    )?;
    bar.finish_and_clear();
    std::fs::write(&a.csv, result.to_csv())
        .with_context(|| format!("cannot write {}", a.csv.display()))?;
    if let Some(png) = &a.png {
        let title = if a.optimize_volumes {
            "MAX PHI OVER VOLUMES"
        } else {
            "PHI"
        };
        let img = mote_rcp::heatmap::render(&result, title);
        let file = std::fs::File::create(png)
            .with_context(|| format!("cannot create {}", png.display()))?;
        img.write_png(std::io::BufWriter::new(file))
            .with_context(|| format!("cannot write {}", png.display()))?;
    }
    let best = (0..result.phi.len())
        .filter(|&i| result.phi[i].is_finite())
        .max_by(|&i, &j| result.phi[i].total_cmp(&result.phi[j]));
    if let Some(b) = best {
        say!(
            "max phi = {:.6} at {} = {}, {} = {}",
            result.phi[b],
            x.param,
            x.value(b % x.count),
            y.param,
            y.value(b / x.count)
        );
    }
    say!("evaluations = {}", result.evaluations);
    if !global.quiet {
        tell!(
            "{} points, {} evaluations in {:.2} s; wrote {}{}",
            points,
            result.evaluations,
            started.elapsed().as_secs_f64(),
            a.csv.display(),
            a.png
                .as_ref()
                .map(|p| format!(" and {}", p.display()))
                .unwrap_or_default()
        );
    }
    Ok(ExitCode::SUCCESS)
}
