//! The runtime of a simulated run: tokio's current-thread scheduler, not paused, whose
//! idle moments move the virtual clock.

use parking_lot::Mutex;
use std::future::Future;
use std::pin::{pin, Pin};
use std::sync::Arc;
use std::task::{Context, Poll, Wake, Waker};
use std::time::Duration;
use tokio::sync::Notify;

use crate::clock::{Advanced, Clock};

/// What a paced clock may not run ahead of: time since the runtime was built.
pub trait Reference: Send + Sync {
    fn now(&self) -> Duration;
}

/// `factor` times the wall clock since it was made: a run at `--speed`.
pub struct Speed {
    factor: f64,
    wall: std::time::Instant,
}

impl Speed {
    pub fn new(factor: f64) -> Speed {
        Speed { factor, wall: std::time::Instant::now() }
    }
}

impl Reference for Speed {
    fn now(&self) -> Duration {
        Duration::try_from_secs_f64(self.wall.elapsed().as_secs_f64() * self.factor)
            .unwrap_or(Duration::MAX)
    }
}

/// How often a held clock looks at its reference again, in real time.
const PACE_POLL: Duration = Duration::from_millis(2);

/// Builds a [`Runtime`].
#[derive(Default)]
pub struct Builder {
    io: bool,
    reference: Option<Arc<dyn Reference>>,
}

impl Builder {
    pub fn new() -> Builder {
        Builder::default()
    }

    /// Sockets (a live run's MAVLink links).
    pub fn enable_io(mut self) -> Builder {
        self.io = true;
        self
    }

    /// The clock never passes `reference`.
    pub fn paced(mut self, reference: Arc<dyn Reference>) -> Builder {
        self.reference = Some(reference);
        self
    }

    pub fn build(self) -> std::io::Result<Runtime> {
        let clock = Clock::default();
        let held = Arc::new(Notify::new());
        let on_park = {
            let (clock, held, reference) = (clock.clone(), held.clone(), self.reference.clone());
            // Called by the scheduler when no task is ready, before it parks the thread:
            // the moment tokio's paused clock would have jumped to its next timer.
            move || {
                let limit = reference.as_ref().map(|r| r.now().as_millis());
                let limit = limit.map(|ms| u64::try_from(ms).unwrap_or(u64::MAX));
                if clock.advance_to_next(limit) == Advanced::Held {
                    held.notify_one();
                }
            }
        };
        let mut tokio = tokio::runtime::Builder::new_current_thread();
        // Tokio's own timer runs in real time: the pacer's waits, and nothing else here.
        tokio.enable_time().on_thread_park(on_park);
        if self.io {
            tokio.enable_io();
        }
        let tokio = tokio.build()?;
        if self.reference.is_some() {
            tokio.spawn(pacer(held));
        }
        Ok(Runtime { tokio, clock })
    }
}

/// While the reference holds the clock, the runtime must still wake to move on when the
/// reference does: a real-time sleep of a few milliseconds each time the park found the
/// next deadline out of reach (a sleep of tokio's own, which is real time: this runtime
/// is not paused).
async fn pacer(held: Arc<Notify>) {
    loop {
        held.notified().await;
        #[allow(clippy::disallowed_methods)] // the pacer waits in real time
        tokio::time::sleep(PACE_POLL).await;
    }
}

/// A runtime with a clock of its own (see the crate's doc).
pub struct Runtime {
    tokio: tokio::runtime::Runtime,
    clock: Clock,
}

impl Runtime {
    /// A simulated run's runtime: no sockets, no pacing.
    pub fn new() -> std::io::Result<Runtime> {
        Builder::new().build()
    }

    /// Its clock, readable from any thread.
    pub fn clock(&self) -> Clock {
        self.clock.clone()
    }

    /// Runs `future` to its end, with this runtime's clock as the thread's.
    pub fn block_on<F: Future>(&self, future: F) -> F::Output {
        let _entered = self.clock.enter();
        let waker = Arc::new(MainWaker { clock: self.clock.clone(), inner: Mutex::new(None) });
        self.tokio.block_on(Main { future: pin!(future), waker })
    }
}

/// The `block_on` future, which marks the clock while it is woken: it must be polled
/// at the instant it was woken, so the clock does not move before then.
struct Main<'a, F: Future> {
    future: Pin<&'a mut F>,
    waker: Arc<MainWaker>,
}

struct MainWaker {
    clock: Clock,
    inner: Mutex<Option<Waker>>,
}

impl Wake for MainWaker {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        self.clock.set_main_woken(true);
        if let Some(w) = &*self.inner.lock() {
            w.wake_by_ref();
        }
    }
}

impl<F: Future> Future for Main<'_, F> {
    type Output = F::Output;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<F::Output> {
        let this = self.get_mut();
        this.waker.clock.set_main_woken(false);
        {
            let mut inner = this.waker.inner.lock();
            if !inner.as_ref().is_some_and(|w| w.will_wake(cx.waker())) {
                *inner = Some(cx.waker().clone());
            }
        }
        let waker = Waker::from(this.waker.clone());
        this.future.as_mut().poll(&mut Context::from_waker(&waker))
    }
}
