//! A scope's queue of work to start (handler instances, leash sections): a plain
//! single-threaded queue and the waker of the scope's `drive`. Every block, capability
//! instance and handler has a scope, so a channel each (an allocation of a block of
//! slots, and atomics) would be the largest cost of starting one; most scopes never get
//! a job.

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::task::{Context, Poll, Waker};

use crate::engine::Job;

#[derive(Default)]
pub(crate) struct Jobs<'m> {
    queue: RefCell<VecDeque<Job<'m>>>,
    waker: Cell<Option<Waker>>,
}

impl<'m> Jobs<'m> {
    /// Queues a job and wakes the scope's `drive`. A job sent once `drive` has ended is
    /// never started (as with a closed channel).
    pub fn send(&self, job: Job<'m>) {
        self.queue.borrow_mut().push_back(job);
        if let Some(waker) = self.waker.take() {
            waker.wake();
        }
    }

    pub fn try_recv(&self) -> Option<Job<'m>> {
        self.queue.borrow_mut().pop_front()
    }

    pub fn poll_recv(&self, cx: &mut Context<'_>) -> Poll<Job<'m>> {
        match self.try_recv() {
            Some(job) => Poll::Ready(job),
            None => {
                self.waker.set(Some(cx.waker().clone()));
                Poll::Pending
            }
        }
    }
}
