//! Cancellation on one thread: a token is cancelled by itself or by any ancestor, and
//! `cancelled()` wakes whoever waits. `tokio_util`'s `CancellationToken` is made for
//! threads: each child, check and drop takes its parent's mutex, and every top-level
//! activity is a child of the mission's one `stop` token, so each step of every actor
//! would take the same lock several times. The engine is one thread: here it is cells and
//! `Rc`s.

use std::cell::{Cell, RefCell};
use std::future::{poll_fn, Future};
use std::pin::pin;
use std::rc::{Rc, Weak};
use std::task::{Context, Poll, Waker};

#[derive(Default)]
struct Node {
    cancelled: Cell<bool>,
    /// Who waits: almost always one task (the activity's own), so one slot and a list
    /// for the rare others.
    waiter: RefCell<Option<Waker>>,
    waiters: RefCell<Vec<Waker>>,
    children: RefCell<Vec<Weak<Node>>>,
}

#[derive(Clone, Default)]
pub(crate) struct Token(Rc<Node>);

impl Token {
    pub fn new() -> Token {
        Token::default()
    }

    /// A token cancelled with this one (or on its own).
    pub fn child_token(&self) -> Token {
        let child = Token::new();
        child.0.cancelled.set(self.0.cancelled.get());
        let mut children = self.0.children.borrow_mut();
        // Forget children that are gone, now and then, so the list stays within twice
        // the live ones.
        if children.len() >= 8 && children.len().is_power_of_two() {
            children.retain(|c| c.strong_count() > 0);
        }
        children.push(Rc::downgrade(&child.0));
        child
    }

    pub fn is_cancelled(&self) -> bool {
        self.0.cancelled.get()
    }

    pub fn cancel(&self) {
        cancel(&self.0);
    }

    /// Ends once the token is cancelled.
    pub async fn cancelled(&self) {
        poll_fn(|cx| {
            if self.0.cancelled.get() {
                return Poll::Ready(());
            }
            self.wake_on_cancel(cx);
            Poll::Pending
        })
        .await
    }

    /// Runs `work` until it ends (`Some`) or the token is cancelled (`None`), the token
    /// looked at first, as a biased `select!` of `cancelled()` and `work` would. Work
    /// that ends in its first poll (an instant step) never registers a waker.
    pub async fn run<T>(&self, work: impl Future<Output = T>) -> Option<T> {
        let mut work = pin!(work);
        poll_fn(|cx| {
            if self.0.cancelled.get() {
                return Poll::Ready(None);
            }
            if let Poll::Ready(out) = work.as_mut().poll(cx) {
                return Poll::Ready(Some(out));
            }
            if self.0.cancelled.get() {
                // Cancelled by the work itself: the `select!` would have been woken by
                // the token and seen it at its next poll; so will this.
                cx.waker().wake_by_ref();
            } else {
                self.wake_on_cancel(cx);
            }
            Poll::Pending
        })
        .await
    }

    fn wake_on_cancel(&self, cx: &Context<'_>) {
        let mut first = self.0.waiter.borrow_mut();
        match &*first {
            None => *first = Some(cx.waker().clone()),
            Some(w) if w.will_wake(cx.waker()) => {}
            Some(_) => {
                let mut waiters = self.0.waiters.borrow_mut();
                if !waiters.iter().any(|w| w.will_wake(cx.waker())) {
                    waiters.push(cx.waker().clone());
                }
            }
        }
    }
}

fn cancel(node: &Rc<Node>) {
    if node.cancelled.replace(true) {
        return;
    }
    if let Some(waker) = node.waiter.take() {
        waker.wake();
    }
    for waker in node.waiters.take() {
        waker.wake();
    }
    let children = node.children.take();
    for child in children.iter().filter_map(Weak::upgrade) {
        cancel(&child);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancelling_reaches_every_descendant_and_not_the_parent() {
        let root = Token::new();
        let child = root.child_token();
        let grandchild = child.child_token();
        let other = root.child_token();
        child.cancel();
        assert!(child.is_cancelled() && grandchild.is_cancelled());
        assert!(!root.is_cancelled() && !other.is_cancelled());
        root.cancel();
        assert!(other.is_cancelled());
        assert!(root.child_token().is_cancelled(), "a child of a cancelled token starts cancelled");
    }

    fn poll_once<F: Future>(f: std::pin::Pin<&mut F>) -> Poll<F::Output> {
        let waker = futures_util::task::noop_waker();
        f.poll(&mut Context::from_waker(&waker))
    }

    #[test]
    fn run_is_a_biased_select_of_cancellation_and_the_work() {
        // Work that ends in its first poll: its output.
        let token = Token::new();
        assert_eq!(poll_once(pin!(token.run(async { 7 }))), Poll::Ready(Some(7)));
        // Cancelled before: the work is not polled at all.
        token.cancel();
        let mut polled = false;
        let work = async {
            polled = true;
        };
        assert_eq!(poll_once(pin!(token.run(work))), Poll::Ready(None));
        assert!(!polled);
        // Cancelled while the work waits: ends at the next poll, without the work.
        let token = Token::new();
        let mut waiting = Box::pin(token.run(std::future::pending::<()>()));
        assert!(poll_once(waiting.as_mut()).is_pending());
        token.cancel();
        assert_eq!(poll_once(waiting.as_mut()), Poll::Ready(None));
        // Work that cancels its own token and then waits: ends at the next poll, as the
        // select! woken by the token would.
        let token = Token::new();
        let mut cancels_itself = Box::pin(token.run(async {
            token.cancel();
            std::future::pending::<()>().await
        }));
        assert!(poll_once(cancels_itself.as_mut()).is_pending());
        assert_eq!(poll_once(cancels_itself.as_mut()), Poll::Ready(None));
    }
}
