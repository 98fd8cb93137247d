//! A failed `accept` (out of file descriptors, EMFILE) does not end the TCP server: the
//! connection that waited is taken once descriptors are free again. This test binary
//! holds only this test, because it lowers the whole process's RLIMIT_NOFILE.

mod common;

use std::fs::File;
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::MavMessage;
use common::{fleet, quick, serve, Gcs};

#[allow(unsafe_code)] // the C call that reads the process's limit
fn limit() -> libc::rlimit {
    let mut l = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes the struct it is given.
    assert_eq!(unsafe { libc::getrlimit(libc::RLIMIT_NOFILE, &mut l) }, 0);
    l
}

#[allow(unsafe_code)] // the C call that sets it
fn set_limit(l: libc::rlimit) {
    // SAFETY: setrlimit reads the struct it is given.
    assert_eq!(unsafe { libc::setrlimit(libc::RLIMIT_NOFILE, &l) }, 0);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_accept_that_fails_for_want_of_descriptors_is_survived() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let original = limit();
    set_limit(libc::rlimit { rlim_cur: original.rlim_cur.min(256), ..original });
    // Every descriptor taken but one, which the client's socket takes: the server's
    // accept then fails with EMFILE.
    let mut hold = Vec::new();
    loop {
        match File::open("/dev/null") {
            Ok(f) => hold.push(f),
            Err(e) if e.raw_os_error() == Some(libc::EMFILE) => break,
            Err(e) => panic!("{e}"),
        }
    }
    hold.pop();
    let stream =
        tokio::net::TcpStream::connect(vehicles.address).await.expect("connected (in the backlog)");
    let mut gcs = Gcs::over(stream, 255, 190);
    let early = gcs.frame(Duration::from_secs(2)).await;
    let accepted_without_a_descriptor = early.is_some();
    // Descriptors back: the connection that waited is taken, and served.
    drop(hold);
    set_limit(original);
    assert!(!accepted_without_a_descriptor, "the server had a descriptor to accept with");
    let beat = gcs
        .wait(1, Duration::from_secs(5), |m| matches!(m, MavMessage::HEARTBEAT(_)).then_some(()))
        .await;
    assert!(beat.is_some(), "the waiting connection was never served");
    // And later ones too.
    let mut later = Gcs::connect(vehicles.address).await;
    let beat = later
        .wait(1, Duration::from_secs(3), |m| matches!(m, MavMessage::HEARTBEAT(_)).then_some(()))
        .await;
    assert!(beat.is_some(), "a new connection was not served");
    vehicles.stop();
}
