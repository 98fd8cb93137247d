//! [`Interval`]: ticks a period apart, on the current runtime's clock.

use std::future::{poll_fn, Future};
use std::pin::Pin;
use std::task::{ready, Context, Poll};
use std::time::Duration;

use crate::sleep::{sleep_until, Instant, Sleep};

/// Tokio's `Interval` with `MissedTickBehavior::Burst` (its default), the only behaviour
/// used here: a tick late by any amount is still followed by the next one a period after
/// its own deadline, so a late task catches up tick by tick and the ticks' instants stay
/// on the grid (the simulator's steps depend on it).
pub struct Interval {
    delay: Sleep,
    period: Duration,
}

/// Ticks at once, then every `period`.
pub fn interval(period: Duration) -> Interval {
    interval_at(Instant::now(), period)
}

/// Ticks at `start`, then every `period`.
pub fn interval_at(start: Instant, period: Duration) -> Interval {
    Interval { delay: sleep_until(start), period }
}

impl Interval {
    /// Waits for the next tick and returns its deadline.
    pub async fn tick(&mut self) -> Instant {
        poll_fn(|cx| self.poll_tick(cx)).await
    }

    pub fn poll_tick(&mut self, cx: &mut Context<'_>) -> Poll<Instant> {
        ready!(Pin::new(&mut self.delay).poll(cx));
        let deadline = self.delay.deadline();
        // Joins the queue again only at the next poll, as tokio's interval.
        self.delay.reset(deadline + self.period);
        Poll::Ready(deadline)
    }

    pub fn period(&self) -> Duration {
        self.period
    }
}
