//! Joining many instances (a `PARALLEL FOR` over a large group, a statement on a group).
//!
//! `join_all` makes every future before it polls the first, so a FOR over N drones held
//! N suspended block futures at once, even when each would finish in its first poll
//! (as W's instant steps do): memory grew with N times the size of a block's future.
//! [`join_eager`] starts them in the same order, one after another, and keeps only those
//! still pending; a finished one is freed at once. Pending ones are then polled when
//! woken, in the order they were woken, as `join_all` does above its small size.
//! Below that size `join_all` polls every pending future at every wake, in index
//! order; callers keep `join_all` there, so small missions run exactly as before.

use std::future::{poll_fn, Future};
use std::task::Poll;

use futures_util::stream::{FuturesUnordered, StreamExt};

/// At most this many futures are joined with `join_all` (its own small-size limit).
pub(crate) const SMALL: usize = 30;

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
