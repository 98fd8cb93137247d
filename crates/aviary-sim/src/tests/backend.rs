//! The backend on the run's clock (`aviary_clock`): simulated time, paced or not.

use std::sync::Arc;
use std::time::Duration;

use aviary_api::{
    Backend, CallEnd, DroneEvent, DroneId, Ending, FlightState, Interrupt, PendingCall,
};
use aviary_clock::Instant;

use super::*;
use crate::{SimBackend, SimOptions};

/// Runs `f` on a simulated run's runtime: the clock moves only when every task waits.
fn simulated<F: std::future::Future>(f: F) -> F::Output {
    aviary_clock::Runtime::new().unwrap().block_on(f)
}

/// Runs `f` on a runtime whose clock never passes `reference`.
fn paced<F: std::future::Future>(reference: Arc<dyn aviary_clock::Reference>, f: F) -> F::Output {
    aviary_clock::Builder::new().paced(reference).build().unwrap().block_on(f)
}

async fn done(call: PendingCall) -> CallEnd {
    call.end.wait().await.expect("the backend answers every call")
}

async fn take_off(sim: &Arc<SimBackend>, alt: f64) {
    assert_eq!(done(sim.call(DroneId(0), &fc(Function::Arm, &[]))).await, CallEnd::Done);
    assert_eq!(
        done(sim.call(DroneId(0), &fc(Function::TakeOff, &[num(alt)]))).await,
        CallEnd::Done
    );
}

#[test]
fn calls_end_at_the_simulated_time_they_take() {
    simulated(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let t0 = Instant::now();
        take_off(&sim, 20.0).await;
        let took = t0.elapsed().as_secs_f64();
        assert!((took - (2.0 + 17.0 / 3.0)).abs() < 0.4, "{took}");
        assert!((sim.time() - took).abs() < 1e-6, "simulated time is the clock's");
        let t1 = Instant::now();
        assert_eq!(
            done(sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(300.0, 400.0)]))).await,
            CallEnd::Done
        );
        let took = t1.elapsed().as_secs_f64();
        assert!((took - (50.0 + 10.0 / 3.0)).abs() < 0.6, "{took}");
        let t = sim.telemetry(DroneId(0));
        assert_eq!(
            (t.position, t.state, t.link),
            ([300.0, 400.0, 20.0], FlightState::Flying, true)
        );
        assert_eq!(sim.telemetry(DroneId(42)).state, FlightState::Lost);
        match done(sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(5000.0, 0.0)]))).await {
            CallEnd::Failed(f) => assert_eq!(f.exception, BuiltinException::GeofenceViolation),
            other => panic!("{other:?}"),
        }
        sim.shutdown().await;
    })
}

#[test]
fn events_are_taken_once_and_detections_arrive() {
    simulated(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let mut events = sim.events().expect("the first taker gets the events");
        assert!(sim.events().is_none());
        take_off(&sim, 20.0).await;
        assert_eq!(
            done(sim.call(DroneId(0), &fc(Function::StartDetection, &[sym("Body")]))).await,
            CallEnd::Done
        );
        assert_eq!(
            done(sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(320.0, 0.0)]))).await,
            CallEnd::Done
        );
        let mut found = Vec::new();
        while let Ok(e) = events.try_recv() {
            if let DroneEvent::Detected { location, .. } = e {
                found.push(location);
            }
        }
        assert_eq!(found, [[100.0, 10.0, 0.0], [300.0, 0.0, 0.0]]);
        sim.shutdown().await;
    })
}

#[test]
fn pause_resume_and_abort_through_the_backend() {
    simulated(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        take_off(&sim, 20.0).await;
        let call = sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(200.0, 0.0)]));
        aviary_clock::sleep(Duration::from_secs(5)).await;
        sim.interrupt(call.id, Interrupt::Pause);
        let held = sim.telemetry(DroneId(0));
        aviary_clock::sleep(Duration::from_secs(10)).await;
        assert_eq!(sim.telemetry(DroneId(0)).position, held.position);
        let Ending::Later(mut end) = call.end else { panic!("a flight does not end at once") };
        assert!(end.try_recv().is_err(), "still in progress");
        sim.interrupt(call.id, Interrupt::Resume);
        assert_eq!(end.await, Ok(CallEnd::Done));
        assert_eq!(sim.telemetry(DroneId(0)).position, [200.0, 0.0, 20.0]);

        let call = sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(0.0, 0.0)]));
        aviary_clock::sleep(Duration::from_secs(3)).await;
        sim.interrupt(call.id, Interrupt::Abort);
        assert_eq!(done(call).await, CallEnd::Interrupted);
        let here = sim.telemetry(DroneId(0));
        aviary_clock::sleep(Duration::from_secs(3)).await;
        assert_eq!(
            (sim.telemetry(DroneId(0)).position, sim.telemetry(DroneId(0)).speed),
            (here.position, 0.0)
        );
        sim.shutdown().await;
    })
}

#[test]
fn the_driver_ends_when_stopped_or_dropped() {
    simulated(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let driver = sim.take_driver().expect("a driver");
        aviary_clock::sleep(Duration::from_secs(1)).await;
        sim.stop();
        aviary_clock::timeout(Duration::from_secs(1), driver)
            .await
            .expect("ends within a tick")
            .expect("no panic");
        let frozen = sim.time();
        aviary_clock::sleep(Duration::from_secs(1)).await;
        assert_eq!(sim.time(), frozen);

        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let driver = sim.take_driver().expect("a driver");
        drop(sim);
        aviary_clock::timeout(Duration::from_secs(1), driver)
            .await
            .expect("ends without an owner")
            .expect("no panic");

        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        aviary_clock::timeout(Duration::from_secs(1), sim.shutdown())
            .await
            .expect("shutdown returns");
    })
}

#[test]
fn a_runtime_with_the_simulator_finishes() {
    let rt = aviary_clock::Runtime::new().unwrap();
    let end = rt.block_on(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        take_off(&sim, 10.0).await;
        let end = done(sim.call(DroneId(0), &fc(Function::Land, &[]))).await;
        sim.shutdown().await;
        end
    });
    drop(rt);
    assert_eq!(end, CallEnd::Done);
}

/// Runs a scripted mission through the backend; the telemetry every 0.25 s.
async fn scripted() -> Vec<Telemetry> {
    let sim = SimBackend::start(&one_drone(), SimOptions::default());
    let log = Arc::new(parking_lot::Mutex::new(Vec::new()));
    let sampler = {
        let (sim, log) = (sim.clone(), log.clone());
        tokio::spawn(async move {
            let mut every = aviary_clock::interval(Duration::from_millis(250));
            for _ in 0..600 {
                every.tick().await;
                log.lock().push(sim.telemetry(DroneId(0)));
            }
        })
    };
    take_off(&sim, 15.0).await;
    done(sim.call(DroneId(0), &fc(Function::StartDetection, &[sym("Body")]))).await;
    let area =
        aviary_api::Value::Area(vec![[50.0, -20.0], [150.0, -20.0], [150.0, 60.0], [50.0, 60.0]]);
    done(sim.call(DroneId(0), &fc(Function::Sweep, &[area, num(20.0)]))).await;
    done(sim.call(DroneId(0), &fc(Function::ReturnToLaunch, &[]))).await;
    sampler.await.unwrap();
    sim.shutdown().await;
    let log = log.lock().clone();
    log
}

#[test]
fn the_backend_is_deterministic() {
    simulated(async {
        let a = scripted().await;
        let b = scripted().await;
        assert_eq!(a.len(), 600);
        assert_eq!(a, b);
    })
}

#[test]
fn speed_paces_against_the_wall_clock() {
    paced(Arc::new(aviary_clock::Speed::new(50.0)), async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let wall = std::time::Instant::now();
        done(sim.call(DroneId(0), &fc(Function::Hover, &[num(2.0)]))).await;
        // 2 s of simulated time at 50x: at least 40 ms of wall time.
        assert!(wall.elapsed() >= Duration::from_millis(39), "{:?}", wall.elapsed());
        sim.shutdown().await;
    })
}

#[test]
fn a_pace_holds_simulated_time_to_its_source() {
    // A source that moves 1 s per look for five looks, then stands still (a vehicle
    // whose clock stopped, heard all the same): the simulated clock gets no further
    // than those 5 s, however long the wall waits.
    let pace = Arc::new(crate::Pace::default());
    let mut looks = 0;
    pace.follow(Box::new(move || {
        looks += 1;
        Some(if looks <= 5 { 1.0 } else { 0.0 })
    }));
    paced(pace, async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let hover = sim.call(DroneId(0), &fc(Function::Hover, &[num(60.0)]));
        // 300 ms of wall time, told from another thread (a wait of this task's own is on
        // the run's clock, which the pace holds).
        let (tx, rx) = tokio::sync::oneshot::channel();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(300));
            let _ = tx.send(());
        });
        rx.await.expect("the wall's 300 ms");
        let t = sim.time();
        assert!((t - 5.0).abs() < 1e-9, "simulated {t} s");
        drop(hover);
        // Not `shutdown`: the driver would end at its next tick, which the pace, standing
        // still, never lets come. The runtime's end drops it.
        sim.stop();
    })
}

#[test]
fn pacing_leaves_the_thread_free_and_the_clock_still() {
    // At a tenth of real time each 0.05 s tick waits 0.5 s of wall time. A message sent
    // from another thread 20 ms into that wait is taken at once by a task on the same
    // thread, not when the wait is over; and the simulated clock has not moved meanwhile.
    paced(Arc::new(aviary_clock::Speed::new(0.1)), async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        let hover = sim.call(DroneId(0), &fc(Function::Hover, &[num(10.0)]));
        aviary_clock::sleep(Duration::from_millis(60)).await;
        let (tx, mut rx) = tokio::sync::mpsc::unbounded_channel();
        let sent = std::time::Instant::now();
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            let _ = tx.send(std::time::Instant::now());
        });
        let simulated = aviary_clock::Instant::now();
        let at = rx.recv().await.expect("the message");
        let late = at.elapsed();
        // Blocked, it would be taken some 450 ms late.
        assert!(late < Duration::from_millis(200), "taken {late:?} after it was sent");
        assert!(
            sent.elapsed() < Duration::from_millis(250),
            "not after a whole tick's wait: {:?}",
            sent.elapsed()
        );
        assert!(
            aviary_clock::Instant::now() - simulated <= Duration::from_millis(50),
            "the clock moved by at most one tick"
        );
        sim.interrupt(hover.id, aviary_api::Interrupt::Abort);
        sim.shutdown().await;
    })
}

#[test]
fn a_call_done_as_it_is_made_ends_now_and_a_flight_later() {
    simulated(async {
        let sim = SimBackend::start(&one_drone(), SimOptions::default());
        assert!(matches!(
            sim.call(DroneId(0), &fc(Function::Arm, &[])).end,
            Ending::Now(CallEnd::Done)
        ));
        take_off(&sim, 20.0).await;
        let flight = sim.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(50.0, 0.0)]));
        assert!(matches!(flight.end, Ending::Later(_)));
        assert_eq!(done(flight).await, CallEnd::Done);
    })
}
