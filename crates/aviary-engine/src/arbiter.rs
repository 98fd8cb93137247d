//! Per-drone resources, first come first served, claimed all at once (docs/LANGUAGE.md, section 6):
//! a request is granted when none of what it needs is held and no earlier waiting
//! request needs any of it, so instances never deadlock and never overtake.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::rc::Rc;

use aviary_api::{DroneId, Resource};
use aviary_ir::TiVec;
use smallvec::SmallVec;
use tokio::sync::oneshot;

pub(crate) type Claim = (DroneId, Resource);
/// What one request needs: a drone's resource or two, kept inline.
pub(crate) type Needs = SmallVec<[Claim; 2]>;

/// What an activity and its ancestors hold (handlers inside it share the claim). Shared,
/// not copied, by an activity that needs nothing more than its parent holds.
#[derive(Clone, Default)]
pub(crate) struct Claims(Option<Rc<[Claim]>>);

impl Claims {
    pub fn contains(&self, claim: &Claim) -> bool {
        self.0.as_deref().is_some_and(|held| held.contains(claim))
    }

    /// These and `more`.
    pub fn with(&self, more: &[Claim]) -> Claims {
        if more.is_empty() {
            return self.clone();
        }
        let held = self.0.as_deref().unwrap_or_default();
        Claims(Some(held.iter().chain(more).copied().collect()))
    }
}

#[derive(Default)]
pub(crate) struct Arbiter {
    held: ClaimSet,
    /// Granted requests by id, with what they hold.
    granted: BTreeMap<u64, Needs>,
    waiting: Vec<(u64, Needs, oneshot::Sender<()>)>,
    next: u64,
}

/// A set of claims as one bit per resource per drone: a claim's test, grant and release
/// are an index and a mask, whatever the fleet's size.
#[derive(Default)]
struct ClaimSet {
    bits: TiVec<DroneId, u8>,
}

impl ClaimSet {
    fn mask(r: Resource) -> u8 {
        1 << (r as u8)
    }

    fn contains(&self, (d, r): &Claim) -> bool {
        self.bits.get(*d).is_some_and(|b| b & Self::mask(*r) != 0)
    }

    fn insert(&mut self, (d, r): Claim) {
        if self.bits.len() <= d.0 {
            self.bits.resize(d.0 + 1, 0);
        }
        self.bits[d] |= Self::mask(r);
    }

    fn remove(&mut self, (d, r): &Claim) {
        if let Some(b) = self.bits.get_mut(*d) {
            *b &= !Self::mask(*r);
        }
    }

    fn extend(&mut self, claims: impl IntoIterator<Item = Claim>) {
        for c in claims {
            self.insert(c);
        }
    }

    #[cfg(test)]
    fn is_empty(&self) -> bool {
        self.bits.iter().all(|b| *b == 0)
    }
}

/// Claims held until dropped. Dropping a request that still waits withdraws it, and one
/// granted but not yet seen by its waiter is given back: cancellation never leaks.
pub(crate) struct Held {
    arbiter: Rc<RefCell<Arbiter>>,
    id: u64,
    /// The claims of a request granted at once (not recorded in `granted`).
    own: Needs,
}

impl Drop for Held {
    fn drop(&mut self) {
        let mut a = self.arbiter.borrow_mut();
        for c in &self.own {
            a.held.remove(c);
        }
        if let Some(claims) = a.granted.remove(&self.id) {
            for c in &claims {
                a.held.remove(c);
            }
        }
        if !a.waiting.is_empty() {
            a.waiting.retain(|(id, _, _)| *id != self.id);
            a.grant();
        }
    }
}

impl Arbiter {
    fn grant(&mut self) {
        let mut blocked = ClaimSet::default();
        let mut i = 0;
        while i < self.waiting.len() {
            let needs = &self.waiting[i].1;
            if needs.iter().all(|c| !self.held.contains(c) && !blocked.contains(c)) {
                let (id, needs, tx) = self.waiting.remove(i);
                self.held.extend(needs.iter().copied());
                self.granted.insert(id, needs);
                let _ = tx.send(());
            } else {
                blocked.extend(needs.iter().copied());
                i += 1;
            }
        }
    }
}

/// `claims` now, when nobody waits and all of it is free (as `grant` would give them);
/// else they are given back.
pub(crate) fn try_acquire(arbiter: &Rc<RefCell<Arbiter>>, claims: Needs) -> Result<Held, Needs> {
    if free(arbiter, &claims) {
        Ok(take(arbiter, claims))
    } else {
        Err(claims)
    }
}

/// Takes `claims` that [`free`] found free, with nothing asked of the arbiter since.
pub(crate) fn take(arbiter: &Rc<RefCell<Arbiter>>, claims: Needs) -> Held {
    debug_assert!(free(arbiter, &claims), "taken claims were free");
    let mut a = arbiter.borrow_mut();
    a.next += 1;
    let id = a.next;
    a.held.extend(claims.iter().copied());
    Held { arbiter: arbiter.clone(), id, own: claims }
}

/// Whether `claims` would be granted now (`try_acquire` would succeed), without taking them.
pub(crate) fn free(arbiter: &RefCell<Arbiter>, claims: &[Claim]) -> bool {
    let a = arbiter.borrow();
    a.waiting.is_empty() && claims.iter().all(|c| !a.held.contains(c))
}

/// Waits for `claims` (all at once, in arrival order) and holds them.
pub(crate) async fn acquire(arbiter: &Rc<RefCell<Arbiter>>, claims: Needs) -> Held {
    // Granted now without a channel to wait on, when it can be.
    let claims = match try_acquire(arbiter, claims) {
        Ok(held) => return held,
        Err(claims) => claims,
    };
    let (tx, rx) = oneshot::channel();
    let id = {
        let mut a = arbiter.borrow_mut();
        a.next += 1;
        let id = a.next;
        a.waiting.push((id, claims, tx));
        a.grant();
        id
    };
    // Made before waiting, so that a drop while waiting withdraws the request.
    let held = Held { arbiter: arbiter.clone(), id, own: Needs::new() };
    // The sender stays in the arbiter until granted, so this ends only by a grant.
    let _ = rx.await;
    held
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::future::Future;
    use std::pin::pin;
    use std::task::{Context, Poll};

    fn poll_once<F: Future>(f: std::pin::Pin<&mut F>) -> Poll<F::Output> {
        let waker = futures_util::task::noop_waker();
        f.poll(&mut Context::from_waker(&waker))
    }

    #[test]
    fn first_come_first_served_all_at_once() {
        let arbiter = Rc::new(RefCell::new(Arbiter::default()));
        let m = |d| (DroneId(d), Resource::Motion);
        let mut first = pin!(acquire(&arbiter, smallvec::smallvec![m(0)]));
        let Poll::Ready(a) = poll_once(first.as_mut()) else { panic!("free: granted at once") };
        // Needs 0 and 1: waits for 0.
        let mut second = pin!(acquire(&arbiter, smallvec::smallvec![m(0), m(1)]));
        assert!(poll_once(second.as_mut()).is_pending());
        // Needs only 1, which is free, but the earlier waiter wants it: no overtaking.
        let mut third = pin!(acquire(&arbiter, smallvec::smallvec![m(1)]));
        assert!(poll_once(third.as_mut()).is_pending());
        drop(a);
        let Poll::Ready(b) = poll_once(second.as_mut()) else { panic!("granted on release") };
        assert!(poll_once(third.as_mut()).is_pending());
        drop(b);
        assert!(poll_once(third.as_mut()).is_ready());
    }

    #[test]
    fn granted_at_once_only_when_free_and_nobody_waits() {
        let arbiter = Rc::new(RefCell::new(Arbiter::default()));
        let m = |d| (DroneId(d), Resource::Motion);
        let Ok(a) = try_acquire(&arbiter, smallvec::smallvec![m(0)]) else { panic!("free") };
        let refused =
            try_acquire(&arbiter, smallvec::smallvec![m(0), m(1)]).err().expect("0 is held");
        assert_eq!(refused.as_slice(), &[m(0), m(1)], "given back whole");
        // Someone waits for 0 and 1: 1 alone is free but not granted past the waiter.
        let mut waiter = pin!(acquire(&arbiter, refused));
        assert!(poll_once(waiter.as_mut()).is_pending());
        assert!(try_acquire(&arbiter, smallvec::smallvec![m(1)]).is_err());
        drop(a);
        assert!(poll_once(waiter.as_mut()).is_ready());
    }

    #[test]
    fn a_cancelled_waiter_leaks_nothing() {
        let arbiter = Rc::new(RefCell::new(Arbiter::default()));
        let m = (DroneId(0), Resource::Motion);
        let mut first = pin!(acquire(&arbiter, smallvec::smallvec![m]));
        let Poll::Ready(a) = poll_once(first.as_mut()) else { panic!() };
        {
            let mut waiter = Box::pin(acquire(&arbiter, smallvec::smallvec![m]));
            assert!(poll_once(waiter.as_mut()).is_pending());
            drop(a); // grants the waiter, which is dropped before it sees the grant
        }
        assert!(arbiter.borrow().held.is_empty(), "the unseen grant was given back");
        let mut again = pin!(acquire(&arbiter, smallvec::smallvec![m]));
        assert!(poll_once(again.as_mut()).is_ready());
    }
}
