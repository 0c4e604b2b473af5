//! The ranks `mpirun` starts, as the run's [`Comm`] (the `mpi` feature,
//! on the `mpi` crate over the system's MPI: Debian's OpenMPI).
//!
//! Paired exchanges are a non-blocking send and a blocking receive
//! (MPI_Isend + MPI_Recv, so no pattern of partners can deadlock); the
//! gather goes to rank 0 message by message in rank order and the
//! broadcast is MPI_Bcast; the maximum is MPI_Allreduce (exact in any
//! order), the sum stays `Comm`'s own, in rank order, so that every rank
//! count adds in one order per count.

use std::sync::Arc;

use mote_run::comm::Comm;
use mpi::collective::SystemOperation;
use mpi::traits::*;

/// The tag of a paired exchange's messages.
const EXCHANGE: mpi::Tag = 1;
/// The tag of a gather's messages.
const GATHER: mpi::Tag = 2;

/// MPI_COMM_WORLD.
struct World(mpi::topology::SimpleCommunicator);

// SAFETY: MPI is started at MPI_THREAD_SERIALIZED and every call on the
// communicator comes from the one thread that runs the command (a run's
// ranks meet outside its parallel sections), so no two calls overlap.
unsafe impl Send for World {}
unsafe impl Sync for World {}

impl World {
    fn at(&self, rank: usize) -> mpi::topology::Process<'_> {
        self.0.process_at_rank(rank as mpi::Rank)
    }
}

impl Comm for World {
    fn rank(&self) -> usize {
        self.0.rank() as usize
    }

    fn size(&self) -> usize {
        self.0.size() as usize
    }

    fn exchange(&self, to: Option<usize>, send: &[f64], from: Option<usize>) -> Vec<f64> {
        mpi::request::scope(|scope| {
            let sent = to.map(|t| self.at(t).immediate_send_with_tag(scope, send, EXCHANGE));
            let got = from.map_or_else(Vec::new, |f| {
                self.at(f).receive_vec_with_tag::<f64>(EXCHANGE).0
            });
            if let Some(request) = sent {
                request.wait();
            }
            got
        })
    }

    fn gather(&self, send: &[f64]) -> Vec<Vec<f64>> {
        if self.rank() != 0 {
            self.at(0).send_with_tag(send, GATHER);
            return Vec::new();
        }
        let mut all = vec![send.to_vec()];
        for r in 1..self.size() {
            all.push(self.at(r).receive_vec_with_tag::<f64>(GATHER).0);
        }
        all
    }

    fn broadcast(&self, data: &[f64]) -> Vec<f64> {
        let root = self.at(0);
        let mut len = data.len() as u64;
        root.broadcast_into(&mut len);
        let mut out = if self.rank() == 0 {
            data.to_vec()
        } else {
            vec![0.0; len as usize]
        };
        root.broadcast_into(&mut out[..]);
        out
    }

    fn max(&self, x: f64) -> f64 {
        let mut top = x;
        self.0.all_reduce_into(&x, &mut top, SystemOperation::max());
        top
    }
}

/// MPI, started for a command and finalised when dropped.
pub struct Mpi {
    universe: mpi::environment::Universe,
    /// The ranks, where there are several (one rank runs as the plain
    /// build does).
    pub ranks: Option<Arc<dyn Comm>>,
}

impl Mpi {
    /// Starts MPI (MPI_Init_thread; one process started without `mpirun`
    /// is a world of one).
    pub fn start() -> anyhow::Result<Self> {
        let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Serialized)
            .ok_or_else(|| anyhow::anyhow!("MPI was started twice"))?;
        let world = universe.world();
        let ranks = (world.size() > 1).then(|| Arc::new(World(world)) as Arc<dyn Comm>);
        Ok(Self { universe, ranks })
    }

    /// Ends every rank of the run at once (MPI_Abort): where rank 0 fails
    /// during a run, the others wait in a measurement it never takes.
    pub fn abort(&self, code: i32) -> ! {
        self.universe.world().abort(code)
    }
}
