//! A signal stops a run after a whole step, with a checkpoint of that step.
//! (Its own test binary: the stop flag is process-wide.)

use mote_io::checkpoint::{self, Checkpoint};
use mote_run::{Checkpoints, Driver, Propagator, Stopped};

/// Counts steps; its "position" is the step number.
struct Counter(u64);

impl Propagator for Counter {
    type Sample = u64;
    type Error = Ended;
    fn step(&self) -> u64 {
        self.0
    }
    fn time(&self) -> f64 {
        self.0 as f64
    }
    fn advance(&mut self) -> Result<(), Ended> {
        self.0 += 1;
        Ok(())
    }
    fn unstable(&self) -> Option<(usize, String)> {
        None
    }
    fn measure(&mut self) -> u64 {
        self.0
    }
    fn save(&mut self, cp: &mut Checkpoint) -> Result<(), Ended> {
        cp.step = self.0;
        cp.positions = vec![[self.0 as f64; 3]];
        cp.velocities = vec![[0.0; 3]];
        Ok(())
    }
}

#[derive(Debug, PartialEq)]
enum Ended {
    Stopped(Stopped),
    Io(String),
}
impl From<Stopped> for Ended {
    fn from(s: Stopped) -> Self {
        Ended::Stopped(s)
    }
}
impl From<mote_io::IoError> for Ended {
    fn from(e: mote_io::IoError) -> Self {
        Ended::Io(e.to_string())
    }
}

#[test]
fn a_signal_stops_after_the_step_with_a_checkpoint_of_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("checkpoint.mote");
    let mut driver = Driver::new();
    driver.checkpoints = Some(Checkpoints {
        writes: true,
        every: 100,
        path: path.clone(),
        template: Checkpoint::default(),
    });
    let mut c = Counter(0);
    let e = driver
        .run(
            &mut c,
            |_| 1000,
            |c| {
                if c.0 == 4 {
                    mote_io::system::request_stop(15);
                }
            },
        )
        .unwrap_err();
    assert_eq!(
        e,
        Ended::Stopped(Stopped::Interrupted {
            signal: 15,
            step: 4,
            time: 4.0
        })
    );
    assert_eq!(checkpoint::read(&path).unwrap().step, 4);
}
