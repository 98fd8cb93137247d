//! Joining futures: the branches of a `PARALLEL` block, the instances of a `PARALLEL FOR`
//! and of a statement on a group. Which branch is polled when decides the order of
//! events at one instant, so the order is defined here, by the engine, not by
//! `futures_util::future::join_all`, which switches its polling at a size private to
//! futures-util.
//!
//! - Up to [`SMALL`] futures: [`join_in_order`] polls every pending one, in index order,
//!   whenever any is woken. Cheap for few, and the simplest order to reason about.
//! - More: each is polled when it is woken, in the order they were woken, so a wake costs
//!   O(1), not O(N). [`join_woken`] makes every future first (a `PARALLEL` block's
//!   branches, few and small); [`join_eager`] starts them one after another and keeps only
//!   those still pending, so a FOR over N drones never holds N suspended block futures
//!   at once when each finishes in its first poll (as W's instant steps do).

use std::future::{poll_fn, Future};
use std::pin::Pin;
use std::task::Poll;

use futures_util::stream::{FuturesOrdered, FuturesUnordered, StreamExt};

/// At most this many futures are joined in index order. The engine's own figure, which
/// decides traces: it is the size up to which `join_all` polls in index order, so the
/// traces of missions are those they had when the engine joined with `join_all`. Users
/// read it in docs/LANGUAGE.md, section 4 ("Order at one instant"); polling every branch
/// at once for all sizes changes traces (a leash's steps at its instant), so it stays.
pub(crate) const SMALL: usize = 30;

/// Runs every future to its end: at every wake, each pending one is polled, in order.
pub(crate) async fn join_in_order<F: Future<Output = ()>>(futures: impl IntoIterator<Item = F>) {
    let mut pending: Vec<Pin<Box<F>>> = futures.into_iter().map(Box::pin).collect();
    poll_fn(|cx| {
        pending.retain_mut(|f| f.as_mut().poll(cx).is_pending());
        if pending.is_empty() {
            Poll::Ready(())
        } else {
            Poll::Pending
        }
    })
    .await;
}

/// Runs every future to its end: all made first, then each polled when woken.
pub(crate) async fn join_woken<F: Future<Output = ()>>(futures: impl IntoIterator<Item = F>) {
    let mut running: FuturesOrdered<F> = futures.into_iter().collect();
    while running.next().await.is_some() {}
}

/// Runs every future of `futures` to its end; they start in order.
pub(crate) async fn join_eager<F: Future<Output = ()>>(futures: impl IntoIterator<Item = F>) {
    let mut running = FuturesUnordered::new();
    for future in futures {
        running.push(future);
        // Polls the new one (and any woken meanwhile); finished ones are dropped here.
        poll_fn(|cx| {
            while let Poll::Ready(Some(())) = running.poll_next_unpin(cx) {}
            Poll::Ready(())
        })
        .await;
    }
    while running.next().await.is_some() {}
}
