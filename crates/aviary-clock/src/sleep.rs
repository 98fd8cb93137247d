//! [`Instant`], [`Sleep`] and [`timeout`]: tokio's, on the current runtime's clock.

use std::future::{Future, IntoFuture};
use std::ops::{Add, AddAssign, Sub};
use std::pin::{pin, Pin};
use std::sync::OnceLock;
use std::task::{ready, Context, Poll};
use std::time::Duration;

use crate::clock::{Clock, Key};

/// A point in time: since the clock began in a [`crate::Runtime`], or since the process
/// first asked for the time elsewhere. Instants of different runtimes do not compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Instant(Duration);

/// The origin of real time outside a runtime of ours.
fn epoch() -> std::time::Instant {
    static EPOCH: OnceLock<std::time::Instant> = OnceLock::new();
    *EPOCH.get_or_init(std::time::Instant::now)
}

/// Whole milliseconds, rounded up as tokio's timer rounds a deadline (a deadline inside a
/// millisecond falls due at its end).
pub(crate) fn ceil_ms(d: Duration) -> u64 {
    u64::try_from(d.as_nanos().div_ceil(1_000_000)).unwrap_or(u64::MAX)
}

impl Instant {
    /// The current runtime's clock, or the wall clock outside one.
    pub fn now() -> Instant {
        Clock::with_current(|clock| match clock {
            Some(clock) => Instant(clock.now()),
            None => Instant(epoch().elapsed()),
        })
    }

    /// Time from `earlier` to this, zero if `earlier` is later.
    pub fn duration_since(&self, earlier: Instant) -> Duration {
        self.0.saturating_sub(earlier.0)
    }

    /// As [`Instant::duration_since`] (std's, too, saturates).
    pub fn saturating_duration_since(&self, earlier: Instant) -> Duration {
        self.duration_since(earlier)
    }

    /// Time since this instant.
    pub fn elapsed(&self) -> Duration {
        Instant::now().duration_since(*self)
    }

    pub fn checked_add(&self, d: Duration) -> Option<Instant> {
        self.0.checked_add(d).map(Instant)
    }

    pub fn checked_sub(&self, d: Duration) -> Option<Instant> {
        self.0.checked_sub(d).map(Instant)
    }

    /// Time since the clock's origin: the run's time, in a simulated run.
    pub fn since_origin(&self) -> Duration {
        self.0
    }

    fn deadline_ms(&self) -> u64 {
        ceil_ms(self.0)
    }
}

/// Saturates: a deadline too far to say is never reached, as tokio's far future.
impl Add<Duration> for Instant {
    type Output = Instant;
    fn add(self, d: Duration) -> Instant {
        Instant(self.0.saturating_add(d))
    }
}

impl AddAssign<Duration> for Instant {
    fn add_assign(&mut self, d: Duration) {
        *self = *self + d;
    }
}

impl Sub<Duration> for Instant {
    type Output = Instant;
    fn sub(self, d: Duration) -> Instant {
        Instant(self.0.saturating_sub(d))
    }
}

impl Sub<Instant> for Instant {
    type Output = Duration;
    fn sub(self, earlier: Instant) -> Duration {
        self.duration_since(earlier)
    }
}

/// A wait until a deadline (tokio's `Sleep`). It joins the clock's queue when first
/// polled, as tokio's registers with its wheel then; dropped, it leaves it, so the clock
/// never moves to a deadline nobody waits for.
#[must_use = "a sleep does nothing unless awaited"]
pub struct Sleep {
    deadline: Instant,
    state: State,
}

enum State {
    /// Not polled since it was made or reset.
    Idle,
    /// In a runtime's queue.
    Virtual {
        clock: Clock,
        key: Key,
    },
    /// Outside a runtime of ours: tokio's real-time timer.
    Real(Pin<Box<tokio::time::Sleep>>),
    Done,
}

/// Waits until `deadline`.
pub fn sleep_until(deadline: Instant) -> Sleep {
    Sleep { deadline, state: State::Idle }
}

/// Waits for `duration` from now (the deadline is taken now, not when first polled).
pub fn sleep(duration: Duration) -> Sleep {
    sleep_until(Instant::now() + duration)
}

impl Sleep {
    pub fn deadline(&self) -> Instant {
        self.deadline
    }

    pub fn is_elapsed(&self) -> bool {
        matches!(self.state, State::Done)
    }

    /// Waits for `deadline` instead; it joins the queue again at the next poll, behind the
    /// timers already there (as tokio's reset).
    pub fn reset(&mut self, deadline: Instant) {
        self.leave();
        self.deadline = deadline;
        self.state = State::Idle;
    }

    fn leave(&mut self) {
        if let State::Virtual { clock, key } = &self.state {
            clock.cancel(*key);
        }
    }

    fn poll_real(&mut self, cx: &mut Context<'_>) -> Poll<()> {
        if let State::Real(real) = &mut self.state {
            ready!(real.as_mut().poll(cx));
            self.state = State::Done;
        }
        Poll::Ready(())
    }
}

impl Future for Sleep {
    type Output = ();

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        let this = self.get_mut();
        if let State::Real(_) = this.state {
            return this.poll_real(cx);
        }
        if let State::Done = this.state {
            return Poll::Ready(());
        }
        // Tokio's sleep spends one unit of the task's budget when it is ready; so does
        // this one, so that a task that does much at one instant yields where it did.
        let coop = ready!(tokio::task::coop::poll_proceed(cx));
        let waiting = match &this.state {
            State::Virtual { clock, key } => clock.rewake(*key, cx.waker()),
            _ => match Clock::current() {
                Some(clock) => match clock.register(this.deadline.deadline_ms(), cx.waker()) {
                    Some(key) => {
                        this.state = State::Virtual { clock, key };
                        true
                    }
                    None => false,
                },
                // Outside a runtime of ours: real time, on tokio's timer.
                #[allow(clippy::disallowed_methods, clippy::disallowed_types)]
                None => {
                    let at = tokio::time::Instant::from_std(epoch() + this.deadline.0);
                    let real = tokio::time::sleep_until(at);
                    this.state = State::Real(Box::pin(real));
                    drop(coop);
                    return this.poll_real(cx);
                }
            },
        };
        if waiting {
            return Poll::Pending;
        }
        this.state = State::Done;
        coop.made_progress();
        Poll::Ready(())
    }
}

impl Drop for Sleep {
    fn drop(&mut self) {
        self.leave();
    }
}

/// A [`timeout`] that ran out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Elapsed;

impl std::fmt::Display for Elapsed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("deadline has elapsed")
    }
}

impl std::error::Error for Elapsed {}

/// `future`'s output, or [`Elapsed`] if `duration` passes first (from now, not from the
/// first poll). The future is polled first, as tokio's.
pub fn timeout<F: IntoFuture>(
    duration: Duration,
    future: F,
) -> impl Future<Output = Result<F::Output, Elapsed>> {
    timeout_at(Instant::now() + duration, future)
}

/// As [`timeout`], until `deadline`.
pub fn timeout_at<F: IntoFuture>(
    deadline: Instant,
    future: F,
) -> impl Future<Output = Result<F::Output, Elapsed>> {
    let future = future.into_future();
    let delay = sleep_until(deadline);
    async move {
        let mut future = pin!(future);
        let mut delay = delay;
        std::future::poll_fn(|cx| {
            if let Poll::Ready(v) = future.as_mut().poll(cx) {
                return Poll::Ready(Ok(v));
            }
            Pin::new(&mut delay).poll(cx).map(|()| Err(Elapsed))
        })
        .await
    }
}
