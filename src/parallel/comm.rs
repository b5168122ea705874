//! Messages between the processes of a run split over several (`decomposition.rs`): the few
//! collective operations it needs, over bytes, and the encoding of numbers into them.
//!
//! [`Comm`] is implemented by [`Solo`] (one process), by [`Threads`] (several simulations in
//! one process, one thread each: how the tests split a run without MPI) and, with the `mpi`
//! feature, over MPI. Every operation is collective: each process calls it, in the same
//! order.

use std::sync::{Arc, Condvar, Mutex};

use glam::{DQuat, DVec3};

/// Where a gather leaves the whole: on every process, or on the first only (the writer of
/// the output: the others then never hold all particles).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reach {
    Everyone,
    Writer,
}

/// The collective operations of a run split over `size` processes.
pub trait Comm: Send + Sync {
    /// This process, from 0.
    fn rank(&self) -> usize;
    /// The number of processes.
    fn size(&self) -> usize;
    /// Sends `send[q]` to each process q and returns what each process sent to this one.
    fn all_to_all(&self, send: Vec<Vec<u8>>) -> Vec<Vec<u8>>;
    /// What every process contributed, by rank (on every process).
    fn all_gather(&self, data: Vec<u8>) -> Vec<Vec<u8>>;

    /// What every process contributed, by rank, on the first process (the writer); nothing
    /// on the others, which so never hold the whole.
    fn gather(&self, data: Vec<u8>) -> Vec<Vec<u8>> {
        let mut send = vec![Vec::new(); self.size()];
        send[0] = data;
        let got = self.all_to_all(send);
        if self.rank() == 0 { got } else { Vec::new() }
    }

    /// [`Comm::all_gather`] or [`Comm::gather`], as `reach` says.
    fn gather_to(&self, reach: Reach, data: Vec<u8>) -> Vec<Vec<u8>> {
        match reach {
            Reach::Everyone => self.all_gather(data),
            Reach::Writer => self.gather(data),
        }
    }

    /// Sends each `(q, message)` of `send` to process q and receives one message from each
    /// process q of `from`, of the length given with it, in that order: messages between
    /// neighbours only. Every process calls it, and `from` names exactly the processes that
    /// send to this one, with the lengths they send.
    fn exchange(&self, send: Vec<(usize, Vec<u8>)>, from: &[(usize, usize)]) -> Vec<Vec<u8>> {
        let mut all = vec![Vec::new(); self.size()];
        for (q, m) in send {
            all[q] = m;
        }
        let mut got = self.all_to_all(all);
        from.iter()
            .map(|&(q, len)| {
                assert_eq!(got[q].len(), len, "the message of process {q}");
                std::mem::take(&mut got[q])
            })
            .collect()
    }

    /// Whether any process says so.
    fn any(&self, flag: bool) -> bool {
        self.all_gather(vec![flag as u8])
            .iter()
            .any(|d| d.first() == Some(&1))
    }

    /// The largest of the processes' values.
    fn max(&self, x: f64) -> f64 {
        self.all_gather(x.to_le_bytes().to_vec())
            .iter()
            .map(|d| Reader::new(d).f64())
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// The sum of the processes' integers (exact, so in any order).
    fn sum_i64(&self, x: &[i64]) -> Vec<i64> {
        let mut w = Writer::default();
        x.iter().for_each(|&v| w.i64(v));
        let mut total = vec![0i64; x.len()];
        for d in self.all_gather(w.0) {
            let mut r = Reader::new(&d);
            for t in &mut total {
                *t = t.wrapping_add(r.i64());
            }
        }
        total
    }
}

/// A run in one process.
#[derive(Clone, Copy, Debug, Default)]
pub struct Solo;

impl Comm for Solo {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_to_all(&self, send: Vec<Vec<u8>>) -> Vec<Vec<u8>> {
        send
    }
    fn all_gather(&self, data: Vec<u8>) -> Vec<Vec<u8>> {
        vec![data]
    }
}

/// What the threads of one [`Threads`] group put down for each other.
struct Hub {
    /// For each sender, its messages to each receiver.
    posted: Mutex<Vec<Vec<Vec<u8>>>>,
    gate: Mutex<Gate>,
    opened: Condvar,
}

/// A barrier that a thread of the group which panics breaks, so that the others panic too
/// instead of waiting for it forever (a test fails, it does not hang).
#[derive(Default)]
struct Gate {
    waiting: usize,
    round: u64,
    broken: bool,
}

impl Hub {
    /// Waits until all `k` threads of the group are here.
    fn wait(&self, k: usize) {
        let broken = || panic!("another thread of the group panicked");
        let mut gate = self.gate.lock().unwrap_or_else(|e| e.into_inner());
        if gate.broken {
            broken();
        }
        let round = gate.round;
        gate.waiting += 1;
        if gate.waiting == k {
            (gate.waiting, gate.round) = (0, round + 1);
            self.opened.notify_all();
            return;
        }
        while gate.round == round && !gate.broken {
            gate = self.opened.wait(gate).unwrap_or_else(|e| e.into_inner());
        }
        if gate.round == round {
            broken();
        }
    }
}

/// One of `k` simulations that run as the processes of one split run, each in a thread of
/// its own: [`Threads::group`] makes the `k` ends.
pub struct Threads {
    rank: usize,
    size: usize,
    hub: Arc<Hub>,
}

impl Threads {
    /// The `k` ends of a group, by rank.
    pub fn group(k: usize) -> Vec<Threads> {
        let hub = Arc::new(Hub {
            posted: Mutex::new(vec![Vec::new(); k]),
            gate: Mutex::new(Gate::default()),
            opened: Condvar::new(),
        });
        (0..k)
            .map(|rank| Threads {
                rank,
                size: k,
                hub: hub.clone(),
            })
            .collect()
    }
}

impl Drop for Threads {
    /// A thread that panics breaks the group's gate: the others panic at it.
    fn drop(&mut self) {
        if std::thread::panicking() {
            let mut gate = self.hub.gate.lock().unwrap_or_else(|e| e.into_inner());
            gate.broken = true;
            self.hub.opened.notify_all();
        }
    }
}

impl Comm for Threads {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn all_to_all(&self, send: Vec<Vec<u8>>) -> Vec<Vec<u8>> {
        assert_eq!(send.len(), self.size, "one message per process");
        self.hub.posted.lock().expect("not poisoned")[self.rank] = send;
        self.hub.wait(self.size);
        let received = {
            let mut posted = self.hub.posted.lock().expect("not poisoned");
            (0..self.size)
                .map(|q| std::mem::take(&mut posted[q][self.rank]))
                .collect()
        };
        // Nobody posts again before everyone has taken theirs.
        self.hub.wait(self.size);
        received
    }
    fn all_gather(&self, data: Vec<u8>) -> Vec<Vec<u8>> {
        self.all_to_all(vec![data; self.size])
    }
}

/// The number of processes and this process's rank, as an MPI launcher (`mpirun`,
/// `mpiexec`, `srun`) tells them in the environment (OpenMPI, MPICH): known before MPI
/// starts, whatever the build, so that a build without MPI can say so and only the first
/// process prints.
pub fn launched() -> Option<(usize, usize)> {
    let var = |names: &[&str]| {
        names
            .iter()
            .find_map(|n| std::env::var(n).ok()?.parse::<usize>().ok())
    };
    let size = var(&["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"])?;
    let rank = var(&["OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"]).unwrap_or(0);
    Some((size, rank))
}

/// The processes of this node (for the default thread count: the cores shared among them).
pub fn processes_on_this_node() -> usize {
    [
        "OMPI_COMM_WORLD_LOCAL_SIZE",
        "MPI_LOCALNRANKS",
        "SLURM_NTASKS_PER_NODE",
    ]
    .iter()
    .find_map(|n| std::env::var(n).ok()?.parse::<usize>().ok())
    .unwrap_or(1)
    .max(1)
}

#[cfg(feature = "mpi")]
pub use over_mpi::{Finalize, Mpi};

#[cfg(feature = "mpi")]
mod over_mpi {
    use mpi::collective::SystemOperation;
    use mpi::datatype::{Partition, PartitionMut};
    use mpi::traits::*;

    /// The tag of [`super::Comm::exchange`]'s messages (the only point-to-point ones).
    const EXCHANGE: mpi::Tag = 7;

    /// The error code a panic aborts the job with (`MPI_Abort`).
    const PANICKED: i32 = 70;

    /// The processes of `mpirun`, over the system's MPI (the `mpi` feature).
    pub struct Mpi {
        world: mpi::topology::SimpleCommunicator,
    }

    /// Finalizes MPI when dropped: held by `main` until the first process has printed the
    /// run's last words. MPI_Finalize waits for every process, so no process exits (and
    /// makes `mpirun` kill the rest) before the first one has written its error or its
    /// "interrupted".
    pub struct Finalize {
        _universe: mpi::environment::Universe,
    }

    // SAFETY: MPI is initialized with MPI_THREAD_SERIALIZED, and the run calls it from one
    // thread at a time (the thread that steps the simulation; `Comm` methods are never
    // called from its parallel loops).
    unsafe impl Send for Mpi {}
    unsafe impl Sync for Mpi {}

    impl Mpi {
        /// Initializes MPI (once per program). Drop the [`Finalize`] after every `Mpi`.
        pub fn init() -> anyhow::Result<(Mpi, Finalize)> {
            let (universe, threading) = mpi::initialize_with_threading(mpi::Threading::Serialized)
                .ok_or_else(|| anyhow::anyhow!("MPI is initialized already"))?;
            anyhow::ensure!(
                threading >= mpi::Threading::Serialized,
                "this MPI library does not allow calls from a thread other than the first"
            );
            // A panic on one process would leave the others waiting in a collective for
            // ever (and the job its allocation): after its message it ends the whole job.
            let message = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                message(info);
                mpi::topology::SimpleCommunicator::world().abort(PANICKED);
            }));
            Ok((
                Mpi {
                    world: universe.world(),
                },
                Finalize {
                    _universe: universe,
                },
            ))
        }
    }

    /// The most bytes one call of a collective moves into or out of a process: MPI's counts
    /// and offsets are 32-bit, so longer messages (a gathered frame of 10^7 particles is
    /// 2.2 GB) go in rounds, each message `chunk` bytes at a time.
    /// (`TINYDEM_MPI_ROUND_BYTES` sets it smaller, for the tests of the rounds.)
    const ROUND: usize = 1 << 30;

    /// The bytes of each message in a round, with `size` processes.
    fn chunk(size: usize) -> usize {
        static ROUND_BYTES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
        let round = ROUND_BYTES.get_or_init(|| {
            let set = std::env::var("TINYDEM_MPI_ROUND_BYTES").ok();
            set.and_then(|b| b.parse().ok()).unwrap_or(ROUND).min(ROUND)
        });
        (round / size).max(1)
    }

    /// The bytes of a message of `len` that round `round` moves, `chunk` at a time.
    fn slice(len: u64, round: usize, chunk: usize) -> std::ops::Range<usize> {
        let len = len as usize;
        (round * chunk).min(len)..((round + 1) * chunk).min(len)
    }

    /// The offsets of consecutive pieces of `counts` bytes.
    fn offsets(counts: &[mpi::Count]) -> Vec<mpi::Count> {
        counts
            .iter()
            .scan(0, |at, &c| {
                let o = *at;
                *at += c;
                Some(o)
            })
            .collect()
    }

    /// `buf`, cut into consecutive pieces of `counts` bytes, appended to `got`'s.
    fn append(got: &mut [Vec<u8>], buf: &[u8], counts: &[mpi::Count]) {
        let mut at = 0;
        for (g, &c) in got.iter_mut().zip(counts) {
            g.extend_from_slice(&buf[at..at + c as usize]);
            at += c as usize;
        }
    }

    /// `len` zero bytes in a real allocation: an empty `Vec`'s pointer is 1, which OpenMPI
    /// takes for MPI_IN_PLACE.
    fn zeros(len: usize) -> Vec<u8> {
        let mut v = Vec::with_capacity(len.max(1));
        v.resize(len, 0);
        v
    }

    /// `data` in a real allocation (see [`zeros`]).
    fn allocated(mut data: Vec<u8>) -> Vec<u8> {
        data.reserve(1);
        data
    }

    fn count(len: usize) -> mpi::Count {
        mpi::Count::try_from(len).expect("a message below 2 GiB")
    }

    impl super::Comm for Mpi {
        fn rank(&self) -> usize {
            self.world.rank() as usize
        }
        fn size(&self) -> usize {
            self.world.size() as usize
        }
        fn all_to_all(&self, send: Vec<Vec<u8>>) -> Vec<Vec<u8>> {
            let lens: Vec<u64> = send.iter().map(|m| m.len() as u64).collect();
            let mut from = vec![0u64; self.size()];
            self.world.all_to_all_into(&lens[..], &mut from[..]);
            let chunk = chunk(self.size());
            let longest = lens.iter().chain(&from).copied().max().unwrap_or(0);
            let mut rounds = 0u64;
            self.world.all_reduce_into(
                &longest.div_ceil(chunk as u64).max(1),
                &mut rounds,
                SystemOperation::max(),
            );
            let mut got: Vec<Vec<u8>> = from
                .iter()
                .map(|&n| Vec::with_capacity(n as usize))
                .collect();
            for round in 0..rounds as usize {
                let part = |m: &[u8]| slice(m.len() as u64, round, chunk);
                let counts: Vec<mpi::Count> = send.iter().map(|m| count(part(m).len())).collect();
                let into: Vec<mpi::Count> = from
                    .iter()
                    .map(|&n| count(slice(n, round, chunk).len()))
                    .collect();
                let flat = allocated(send.iter().flat_map(|m| &m[part(m)]).copied().collect());
                let mut buf = zeros(into.iter().map(|&c| c as usize).sum());
                {
                    let out = Partition::new(&flat[..], &counts[..], offsets(&counts));
                    let into_offsets = offsets(&into);
                    let mut into = PartitionMut::new(&mut buf[..], &into[..], into_offsets);
                    self.world.all_to_all_varcount_into(&out, &mut into);
                }
                append(&mut got, &buf, &into);
            }
            got
        }
        fn exchange(&self, send: Vec<(usize, Vec<u8>)>, from: &[(usize, usize)]) -> Vec<Vec<u8>> {
            let rank = |q: usize| self.world.process_at_rank(q as mpi::Rank);
            // The receives posted first, into buffers of the known lengths, so that no
            // message waits in MPI's own buffers for its receive.
            let mut got: Vec<Vec<u8>> = from.iter().map(|&(_, len)| zeros(len)).collect();
            mpi::request::scope(|scope| {
                let receiving: Vec<_> = got
                    .iter_mut()
                    .zip(from)
                    .map(|(buf, &(q, _))| {
                        rank(q).immediate_receive_into_with_tag(scope, &mut buf[..], EXCHANGE)
                    })
                    .collect();
                let sending: Vec<_> = send
                    .iter()
                    .map(|(q, m)| rank(*q).immediate_send_with_tag(scope, &m[..], EXCHANGE))
                    .collect();
                for r in receiving {
                    r.wait();
                }
                for r in sending {
                    r.wait();
                }
            });
            got
        }
        fn any(&self, flag: bool) -> bool {
            let mut any = false;
            self.world
                .all_reduce_into(&flag, &mut any, SystemOperation::logical_or());
            any
        }
        fn max(&self, x: f64) -> f64 {
            let mut max = f64::NEG_INFINITY;
            self.world
                .all_reduce_into(&x, &mut max, SystemOperation::max());
            max
        }
        fn sum_i64(&self, x: &[i64]) -> Vec<i64> {
            if x.is_empty() {
                return Vec::new();
            }
            let mut total = vec![0i64; x.len()];
            self.world
                .all_reduce_into(x, &mut total[..], SystemOperation::sum());
            total
        }
        fn all_gather(&self, data: Vec<u8>) -> Vec<Vec<u8>> {
            let mut lens = vec![0u64; self.size()];
            self.world
                .all_gather_into(&(data.len() as u64), &mut lens[..]);
            let chunk = chunk(self.size());
            let longest = lens.iter().copied().max().unwrap_or(0);
            let rounds = longest.div_ceil(chunk as u64).max(1) as usize;
            let mut got: Vec<Vec<u8>> = lens
                .iter()
                .map(|&n| Vec::with_capacity(n as usize))
                .collect();
            for round in 0..rounds {
                let counts: Vec<mpi::Count> = lens
                    .iter()
                    .map(|&n| count(slice(n, round, chunk).len()))
                    .collect();
                let mine = allocated(data[slice(data.len() as u64, round, chunk)].to_vec());
                let mut buf = zeros(counts.iter().map(|&c| c as usize).sum());
                {
                    let at = offsets(&counts);
                    let mut into = PartitionMut::new(&mut buf[..], &counts[..], at);
                    self.world.all_gather_varcount_into(&mine[..], &mut into);
                }
                append(&mut got, &buf, &counts);
            }
            got
        }
    }
}

/// Numbers into bytes (little-endian), for messages.
#[derive(Clone, Debug, Default)]
pub struct Writer(pub Vec<u8>);

impl Writer {
    pub fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    pub fn u16(&mut self, v: u16) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn i64(&mut self, v: i64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub fn vec3(&mut self, v: DVec3) {
        v.to_array().iter().for_each(|&c| self.f64(c));
    }
    pub fn quat(&mut self, q: DQuat) {
        q.to_array().iter().for_each(|&c| self.f64(c));
    }
    pub fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.0.extend_from_slice(b);
    }
}

/// Numbers out of bytes written by a [`Writer`], in the same order. Reading past the end is
/// a bug of the program (the processes disagree on a message), so it panics.
pub struct Reader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Reader { data, at: 0 }
    }
    pub fn done(&self) -> bool {
        self.at >= self.data.len()
    }
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let b = self.data[self.at..self.at + N].try_into().expect("N bytes");
        self.at += N;
        b
    }
    pub fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.take())
    }
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    pub fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.take())
    }
    pub fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
    pub fn vec3(&mut self) -> DVec3 {
        DVec3::new(self.f64(), self.f64(), self.f64())
    }
    pub fn quat(&mut self) -> DQuat {
        DQuat::from_xyzw(self.f64(), self.f64(), self.f64(), self.f64())
    }
    /// The next `n` bytes: a record that its type reads.
    pub fn record(&mut self, n: usize) -> &'a [u8] {
        let b = &self.data[self.at..self.at + n];
        self.at += n;
        b
    }
    pub fn bytes(&mut self) -> &'a [u8] {
        let n = self.u64() as usize;
        let b = &self.data[self.at..self.at + n];
        self.at += n;
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thread of a group that panics makes the others panic at their next exchange,
    /// instead of leaving them waiting for it forever.
    #[test]
    fn a_thread_that_panics_breaks_its_group() {
        let handles: Vec<_> = Threads::group(3)
            .into_iter()
            .map(|c| {
                std::thread::spawn(move || {
                    c.all_gather(vec![1]);
                    if c.rank() == 1 {
                        panic!("rank 1 fails");
                    }
                    c.all_gather(vec![2]);
                })
            })
            .collect();
        let ends: Vec<bool> = handles.into_iter().map(|h| h.join().is_err()).collect();
        assert_eq!(ends, vec![true; 3]);
    }

    #[test]
    fn threads_exchange_what_each_sends_to_each() {
        let ends = Threads::group(3);
        let handles: Vec<_> = ends
            .into_iter()
            .map(|c| {
                std::thread::spawn(move || {
                    let r = c.rank() as u8;
                    let got = c.all_to_all((0..3).map(|q| vec![r, q as u8]).collect());
                    let all = c.all_gather(vec![r * 10]);
                    let first = c.gather(vec![r; 2]);
                    match r {
                        0 => assert_eq!(first, vec![vec![0; 2], vec![1; 2], vec![2; 2]]),
                        _ => assert!(first.is_empty(), "only the first holds them all"),
                    }
                    let total = c.sum_i64(&[r as i64, 1]);
                    (got, all, total, c.any(r == 2), c.max(r as f64))
                })
            })
            .collect();
        for (rank, h) in handles.into_iter().enumerate() {
            let (got, all, total, any, max) = h.join().expect("no panic");
            let expected: Vec<Vec<u8>> = (0..3).map(|q| vec![q as u8, rank as u8]).collect();
            assert_eq!(got, expected);
            assert_eq!(all, vec![vec![0], vec![10], vec![20]]);
            assert_eq!(total, vec![3, 3]);
            assert!(any);
            assert_eq!(max, 2.0);
        }
    }

    #[test]
    fn numbers_read_back_as_written() {
        let mut w = Writer::default();
        w.u8(7);
        w.u16(65000);
        w.u32(123456789);
        w.f64(-0.1);
        w.vec3(DVec3::new(1.0, -2.0, f64::MIN_POSITIVE));
        w.quat(DQuat::from_xyzw(0.5, 0.5, -0.5, 0.5));
        w.bytes(b"abc");
        w.i64(-5);
        let mut r = Reader::new(&w.0);
        assert_eq!(r.u8(), 7);
        assert_eq!(r.u16(), 65000);
        assert_eq!(r.u32(), 123456789);
        assert_eq!(r.f64(), -0.1);
        assert_eq!(r.vec3(), DVec3::new(1.0, -2.0, f64::MIN_POSITIVE));
        assert_eq!(r.quat(), DQuat::from_xyzw(0.5, 0.5, -0.5, 0.5));
        assert_eq!(r.bytes(), b"abc");
        assert_eq!(r.i64(), -5);
        assert!(r.done());
    }
}
