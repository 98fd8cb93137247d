//! The virtual clock: whole milliseconds since the runtime began, and the timers waiting
//! on it, in the order they will wake.

use parking_lot::Mutex;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::task::Waker;
use std::time::Duration;

/// A timer's place in the queue: its deadline in whole milliseconds, then the order in
/// which timers were registered, so that timers due at one instant wake first in, first
/// out, as tokio's wheel wakes them.
pub(crate) type Key = (u64, u64);

/// One runtime's clock. A cheap handle (an `Arc`): [`Clock::now`] may be read from any
/// thread (the operator server reads the run's time while the engine runs).
#[derive(Clone, Default)]
pub struct Clock {
    shared: Arc<Shared>,
}

#[derive(Default)]
struct Shared {
    /// Milliseconds since the clock began. Written under `timers`' lock, read without it.
    now: AtomicU64,
    timers: Mutex<Timers>,
    /// The `block_on` future was woken and not yet polled: it must run at this instant,
    /// so the clock may not move (tokio's paused clock does not advance when the runtime
    /// was unparked either).
    main_woken: AtomicBool,
}

#[derive(Default)]
struct Timers {
    next_seq: u64,
    waiting: BTreeMap<Key, Waker>,
}

/// What [`Clock::advance_to_next`] did.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Advanced {
    /// Moved to the earliest deadline and woke every timer due there.
    Moved,
    /// The earliest deadline is beyond the limit: nothing moved.
    Held,
    /// No timer waits, or the clock may not move now.
    Nothing,
}

thread_local! {
    /// The clock of the runtime whose `block_on` runs on this thread. A thread-local rather
    /// than a handle passed down: the engine, the simulator and the MAVLink backend read
    /// the time and sleep deep in code that knows no runtime, as they did with tokio's own
    /// (whose handle is a thread-local too); and a current-thread runtime runs all its
    /// tasks on the thread of its `block_on`, so one thread means one clock, while runtimes
    /// on other threads (tests in parallel, campaigns on J threads) keep theirs.
    static CURRENT: RefCell<Option<Clock>> = const { RefCell::new(None) };
}

impl Clock {
    /// The clock of the runtime this thread runs, if any.
    pub fn current() -> Option<Clock> {
        CURRENT.with(|c| c.borrow().clone())
    }

    /// Runs `f` with the current clock, without cloning its handle (the hot path).
    pub(crate) fn with_current<R>(f: impl FnOnce(Option<&Clock>) -> R) -> R {
        CURRENT.with(|c| f(c.borrow().as_ref()))
    }

    /// Makes this the thread's clock until the guard drops (the one before comes back).
    pub(crate) fn enter(&self) -> EnterGuard {
        let before = CURRENT.with(|c| c.borrow_mut().replace(self.clone()));
        EnterGuard { before }
    }

    /// Time since the clock began, in whole milliseconds.
    pub fn now(&self) -> Duration {
        Duration::from_millis(self.now_ms())
    }

    pub(crate) fn now_ms(&self) -> u64 {
        self.shared.now.load(Ordering::Acquire)
    }

    /// Registers a timer for `deadline` (whole ms) and returns its key; `None` when it is
    /// already due, as tokio fires a timer registered for a passed instant at once.
    pub(crate) fn register(&self, deadline: u64, waker: &Waker) -> Option<Key> {
        let mut t = self.shared.timers.lock();
        if deadline <= self.now_ms() {
            return None;
        }
        let key = (deadline, t.next_seq);
        t.next_seq += 1;
        t.waiting.insert(key, waker.clone());
        Some(key)
    }

    /// A registered timer polled again: keeps its place, takes the newest waker. `false`
    /// when it has been woken (taken off the queue) meanwhile.
    pub(crate) fn rewake(&self, key: Key, waker: &Waker) -> bool {
        let mut t = self.shared.timers.lock();
        match t.waiting.get_mut(&key) {
            Some(w) => {
                if !w.will_wake(waker) {
                    w.clone_from(waker);
                }
                true
            }
            None => false,
        }
    }

    /// A timer dropped before it fired: the clock must not move to its deadline for it.
    pub(crate) fn cancel(&self, key: Key) {
        self.shared.timers.lock().waiting.remove(&key);
    }

    pub(crate) fn set_main_woken(&self, woken: bool) {
        self.shared.main_woken.store(woken, Ordering::Release);
    }

    /// The idle runtime's step: to the earliest deadline, if it is within `limit` (whole
    /// ms, `None` for no limit), waking every timer due there in order.
    pub(crate) fn advance_to_next(&self, limit: Option<u64>) -> Advanced {
        if self.shared.main_woken.load(Ordering::Acquire) {
            return Advanced::Nothing;
        }
        let mut t = self.shared.timers.lock();
        let Some(((at, _), _)) = t.waiting.first_key_value() else { return Advanced::Nothing };
        let at = *at;
        if limit.is_some_and(|limit| at > limit) {
            return Advanced::Held;
        }
        let due = self.take_due(&mut t, at);
        drop(t);
        due.into_iter().for_each(Waker::wake);
        Advanced::Moved
    }

    /// Sets the clock to `to` (never back) and takes the wakers due by then, in order.
    fn take_due(&self, t: &mut Timers, to: u64) -> Vec<Waker> {
        let to = to.max(self.now_ms());
        self.shared.now.store(to, Ordering::Release);
        let later = t.waiting.split_off(&(to + 1, 0));
        std::mem::replace(&mut t.waiting, later).into_values().collect()
    }

    /// Moves the clock on by `by` (rounded up to whole ms), waking what falls due.
    fn advance_by(&self, by: Duration) {
        let mut t = self.shared.timers.lock();
        let to = self.now_ms().saturating_add(crate::sleep::ceil_ms(by));
        let due = self.take_due(&mut t, to);
        drop(t);
        due.into_iter().for_each(Waker::wake);
    }
}

/// Restores the thread's clock of before [`Clock::enter`].
pub(crate) struct EnterGuard {
    before: Option<Clock>,
}

impl Drop for EnterGuard {
    fn drop(&mut self) {
        let before = self.before.take();
        CURRENT.with(|c| *c.borrow_mut() = before);
    }
}

/// Moves this thread's clock on by `by` at once, waking every timer that falls due, then
/// yields so that they run: the tests' way to put time forward by hand (tokio's
/// `time::advance`). Without a clock (outside a [`crate::Runtime`]) it only yields.
pub async fn advance(by: Duration) {
    if let Some(clock) = Clock::current() {
        clock.advance_by(by);
    }
    tokio::task::yield_now().await;
}
