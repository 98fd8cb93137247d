//! The clock by time and order: what wakes when, in which order, and how far a paced
//! clock may go.

use aviary_clock::{
    advance, interval_at, sleep, sleep_until, timeout, Builder, Instant, Reference, Runtime,
};
use std::cell::RefCell;
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

/// Milliseconds of the current clock since its origin.
fn now_ms() -> u128 {
    Instant::now().since_origin().as_millis()
}

#[test]
fn timers_due_at_one_instant_wake_in_the_order_they_were_registered() {
    let rt = Runtime::new().unwrap();
    let order = rt.block_on(async {
        let log = Rc::new(RefCell::new(Vec::new()));
        let at = Instant::now() + ms(100);
        let local = tokio::task::LocalSet::new();
        // Registered c, a, b (each at its first poll), all for 100 ms; d earlier, e later.
        for (name, wait) in [("c", 0), ("a", 10), ("b", 20)] {
            let log = log.clone();
            local.spawn_local(async move {
                sleep(ms(wait)).await;
                sleep_until(at).await;
                log.borrow_mut().push((name, now_ms()));
            });
        }
        for (name, deadline) in [("e", 150), ("d", 50)] {
            let log = log.clone();
            local.spawn_local(async move {
                sleep(ms(deadline)).await;
                log.borrow_mut().push((name, now_ms()));
            });
        }
        local.await;
        log.take()
    });
    assert_eq!(order, [("d", 50), ("c", 100), ("a", 100), ("b", 100), ("e", 150)]);
}

#[test]
fn deadlines_round_up_to_whole_milliseconds() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        sleep(Duration::from_micros(1_500)).await;
        assert_eq!(Instant::now().since_origin(), ms(2), "1.5 ms falls due at 2 ms");
        sleep(Duration::from_nanos(1)).await;
        assert_eq!(Instant::now().since_origin(), ms(3), "a nanosecond is a millisecond");
        sleep(ms(7)).await;
        assert_eq!(Instant::now().since_origin(), ms(10), "a whole millisecond stays");
        // A deadline already passed (or now) does not move the clock.
        sleep(Duration::ZERO).await;
        sleep_until(Instant::now() - ms(5)).await;
        assert_eq!(Instant::now().since_origin(), ms(10));
        // The instant itself keeps its fraction; only the wait rounds.
        let at = Instant::now() + Duration::from_micros(250);
        assert_eq!(at.since_origin(), Duration::from_micros(10_250));
        sleep_until(at).await;
        assert_eq!(Instant::now().since_origin(), ms(11));
    });
}

#[test]
fn an_idle_runtime_jumps_to_the_next_deadline_at_once() {
    let rt = Runtime::new().unwrap();
    let wall = std::time::Instant::now();
    let steps = rt.block_on(async {
        let mut steps = Vec::new();
        for _ in 0..3 {
            sleep(Duration::from_secs(3_600)).await;
            steps.push(now_ms());
        }
        steps
    });
    assert_eq!(steps, [3_600_000, 7_200_000, 10_800_000]);
    assert!(wall.elapsed() < Duration::from_secs(5), "three hours took {:?}", wall.elapsed());
    assert_eq!(rt.clock().now(), Duration::from_secs(10_800), "read from outside the run");
}

#[test]
fn a_dropped_sleep_does_not_move_the_clock() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        tokio::select! {
            biased;
            _ = sleep(ms(10)) => {}
            _ = sleep(ms(1_000)) => unreachable!(),
        }
        sleep(ms(5)).await;
        assert_eq!(now_ms(), 15, "the clock went to the dropped sleep's deadline");
    });
}

#[test]
fn the_main_future_woken_at_an_instant_runs_at_that_instant() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        let (tx, rx) = tokio::sync::oneshot::channel();
        tokio::spawn(async move {
            sleep(ms(10)).await;
            let _ = tx.send(now_ms());
        });
        // Another timer waits further on: the clock must not go there before the main
        // future, woken at 10 ms by the task, has run.
        tokio::spawn(sleep(ms(20)));
        let sent = rx.await.unwrap();
        assert_eq!((sent, now_ms()), (10, 10));
    });
}

#[test]
fn a_timeout_ends_at_its_deadline_or_with_its_future() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        let r = timeout(ms(5_000), std::future::pending::<()>()).await;
        assert!(r.is_err());
        assert_eq!(now_ms(), 5_000);
        let r = timeout(ms(5_000), async {
            sleep(ms(1_000)).await;
            7
        })
        .await;
        assert_eq!(r, Ok(7));
        assert_eq!(now_ms(), 6_000, "the future's end, not the deadline");
        // The deadline is taken when the timeout is made, not when first polled.
        let late = timeout(ms(100), std::future::pending::<()>());
        sleep(ms(60)).await;
        assert!(late.await.is_err());
        assert_eq!(now_ms(), 6_100);
    });
}

#[test]
fn a_late_interval_bursts_on_its_grid() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        let mut every = interval_at(Instant::now() + ms(50), ms(50));
        let mut ticks = Vec::new();
        let mut seen = Vec::new();
        for step in 0..5 {
            let at = every.tick().await;
            ticks.push(at.since_origin().as_millis());
            seen.push(now_ms());
            if step == 0 {
                sleep(ms(120)).await; // late for two ticks
            }
        }
        assert_eq!(ticks, [50, 100, 150, 200, 250]);
        assert_eq!(seen, [50, 170, 170, 200, 250], "the missed ticks come at once");
    });
}

#[test]
fn advance_moves_the_clock_by_hand_and_wakes_what_falls_due() {
    let rt = Runtime::new().unwrap();
    rt.block_on(async {
        let woke = tokio::spawn(async {
            sleep(ms(50)).await;
            now_ms()
        });
        tokio::task::yield_now().await; // the task registers its sleep
        advance(Duration::from_micros(100_400)).await;
        assert_eq!(now_ms(), 101, "rounded up");
        assert_eq!(woke.await.unwrap(), 101, "woken by the advance, at its time");
    });
}

/// A reference the test moves by hand.
#[derive(Default)]
struct Hand(AtomicU64);

impl Reference for Hand {
    fn now(&self) -> Duration {
        ms(self.0.load(Ordering::SeqCst))
    }
}

#[test]
fn a_paced_clock_never_runs_ahead_of_its_reference() {
    let hand = Arc::new(Hand::default());
    let rt = Builder::new().paced(hand.clone()).build().unwrap();
    let mover = {
        let hand = hand.clone();
        std::thread::spawn(move || {
            // 35 ms of reference every 20 ms of wall, up to 400.
            for step in 1..=12u64 {
                std::thread::sleep(ms(20));
                hand.0.store((step * 35).min(400), Ordering::SeqCst);
            }
        })
    };
    let wall = std::time::Instant::now();
    let seen = rt.block_on(async {
        let mut seen = Vec::new();
        for _ in 0..4 {
            sleep(ms(100)).await;
            seen.push((now_ms(), u128::from(hand.0.load(Ordering::SeqCst))));
        }
        seen
    });
    mover.join().unwrap();
    let clock: Vec<_> = seen.iter().map(|(c, _)| *c).collect();
    assert_eq!(clock, [100, 200, 300, 400], "the deadlines themselves, not the reference");
    for (clock, reference) in &seen {
        assert!(clock <= reference, "clock {clock} ms ran ahead of the reference {reference} ms");
    }
    // 400 ms of reference arrive after 12 steps of 20 ms of wall: the run waited for it.
    assert!(wall.elapsed() >= ms(200), "the run took {:?}", wall.elapsed());
}

#[test]
fn a_held_clock_still_serves_tasks_woken_from_elsewhere() {
    // The reference stands at zero: the clock may not move, yet a message from another
    // thread (an operator's) is heard at once.
    let rt = Builder::new().paced(Arc::new(Hand::default())).build().unwrap();
    let (tx, rx) = tokio::sync::oneshot::channel();
    let sender = std::thread::spawn(move || {
        std::thread::sleep(ms(30));
        tx.send(()).unwrap();
    });
    let heard = rt.block_on(async {
        tokio::spawn(sleep(ms(10))); // a deadline the reference holds back
        rx.await.unwrap();
        now_ms()
    });
    sender.join().unwrap();
    assert_eq!(heard, 0);
}

#[test]
fn each_runtime_has_its_own_clock() {
    let runs: Vec<_> = [30u64, 70]
        .into_iter()
        .map(|step| {
            std::thread::spawn(move || {
                let rt = Runtime::new().unwrap();
                rt.block_on(async move {
                    for _ in 0..100 {
                        sleep(ms(step)).await;
                        tokio::task::yield_now().await;
                    }
                    now_ms()
                })
            })
        })
        .collect();
    let ends: Vec<_> = runs.into_iter().map(|r| r.join().unwrap()).collect();
    assert_eq!(ends, [3_000, 7_000]);
}

#[test]
fn outside_a_runtime_of_ours_time_is_real() {
    let rt = tokio::runtime::Builder::new_current_thread().enable_time().build().unwrap();
    rt.block_on(async {
        let start = Instant::now();
        let wall = std::time::Instant::now();
        sleep(ms(30)).await;
        assert!(wall.elapsed() >= ms(30), "slept {:?}", wall.elapsed());
        assert!(start.elapsed() >= ms(30));
        assert!(timeout(ms(20), std::future::pending::<()>()).await.is_err());
        assert!(wall.elapsed() >= ms(50));
    });
}
