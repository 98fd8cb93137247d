//! A campaign as a Slurm job array (docs/CAMPAIGNS.md): the test starts a one-node Slurm
//! cluster of its own (munged, slurmctld and slurmd as its child processes, with a
//! slurm.conf in a scratch folder, on loopback ports of their own), submits
//! `aviary test ... --shard $SLURM_ARRAY_TASK_ID/N --format json` as an array of N tasks,
//! waits for it, merges the shards' reports and compares the merge with an unsharded run,
//! byte for byte. It needs Debian's `slurm-wlm` and `munge` (`.ci/run` installs them);
//! where their programs are missing it says so in one line and passes, as the
//! real-autopilot suites do where no autopilot is named.

mod common;

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{aviary, repo, scratch, wait_at_most};

const PROGRAMS: [&str; 5] = ["munged", "slurmctld", "slurmd", "sbatch", "sinfo"];
const SHARDS: u32 = 3;
const RUNS: &str = "12";

/// Where `program` is on the PATH (or in the sbin folders, where Debian puts daemons).
fn find(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH").unwrap_or_default();
    std::env::split_paths(&path)
        .chain(["/usr/sbin", "/sbin", "/usr/local/sbin"].map(PathBuf::from))
        .map(|dir| dir.join(program))
        .find(|p| p.is_file())
}

/// The cluster's processes: ended, each by its own id, when the test ends.
struct Cluster {
    children: Vec<(&'static str, Child)>,
    dir: PathBuf,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for (_, child) in self.children.iter_mut().rev() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

impl Cluster {
    fn log(&self, name: &str) -> String {
        std::fs::read_to_string(self.dir.join(name)).unwrap_or_default()
    }

    fn logs(&self) -> String {
        ["munged.log", "slurmctld.log", "slurmd.log"]
            .map(|l| format!("--- {l}:\n{}", self.log(l)))
            .join("\n")
    }

    /// A Slurm client command with this cluster's configuration.
    fn client(&self, program: &Path) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.dir.join("slurm.conf"));
        c
    }
}

/// A loopback port nobody listens on now.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free port")
}

fn start(program: &Path, args: &[&str], dir: &Path) -> Child {
    Command::new(program)
        .args(args)
        .env("SLURM_CONF", dir.join("slurm.conf"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {}: {e}", program.display()))
}

fn cluster(bin: &dyn Fn(&str) -> PathBuf) -> Cluster {
    let dir = scratch("slurm_cluster");
    for sub in ["state", "spool"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    // munge's key: 1 KiB of randomness, readable by its owner only.
    let key = dir.join("munge.key");
    let mut bytes = Vec::new();
    {
        use std::io::Read;
        std::fs::File::open("/dev/urandom").unwrap().take(1024).read_to_end(&mut bytes).unwrap();
    }
    std::fs::write(&key, &bytes).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o400)).unwrap();
    let host = String::from_utf8(Command::new("hostname").arg("-s").output().unwrap().stdout)
        .unwrap()
        .trim()
        .to_owned();
    let d = dir.display();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let user = String::from_utf8(Command::new("id").arg("-un").output().unwrap().stdout).unwrap();
    let user = user.trim();
    let conf = format!(
        "ClusterName=aviarytest\n\
         SlurmctldHost={host}(127.0.0.1)\n\
         SlurmUser={user}\nSlurmdUser={user}\n\
         SlurmctldPort={}\nSlurmdPort={}\n\
         AuthType=auth/munge\nAuthInfo=socket={d}/munge.socket\nCryptoType=crypto/munge\n\
         StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\n\
         SlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
         SlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\n\
         ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
         SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nSchedulerType=sched/builtin\n\
         ReturnToService=2\nMpiDefault=none\n\
         JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n\
         NodeName=aviary NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
         PartitionName=campaign Nodes=aviary Default=YES MaxTime=INFINITE State=UP\n",
        free_port(),
        free_port()
    );
    std::fs::write(dir.join("slurm.conf"), conf).unwrap();
    let mut cluster = Cluster { children: Vec::new(), dir: dir.clone() };
    let munged = start(
        &bin("munged"),
        &[
            "-F",
            "--force",
            &format!("--key-file={d}/munge.key"),
            &format!("--socket={d}/munge.socket"),
            &format!("--pid-file={d}/munged.pid"),
            &format!("--log-file={d}/munged.log"),
            &format!("--seed-file={d}/munged.seed"),
        ],
        &dir,
    );
    cluster.children.push(("munged", munged));
    wait_for(&cluster, "munge's socket", || dir.join("munge.socket").exists());
    let conf = format!("{d}/slurm.conf");
    let ctld = start(&bin("slurmctld"), &["-D", "-f", &conf], &dir);
    cluster.children.push(("slurmctld", ctld));
    let slurmd = start(&bin("slurmd"), &["-D", "-N", "aviary", "-f", &conf], &dir);
    cluster.children.push(("slurmd", slurmd));
    let sinfo = bin("sinfo");
    wait_for(&cluster, "the node to be idle", || {
        let out = cluster.client(&sinfo).args(["-h", "-N", "-o", "%t"]).output();
        out.is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
    });
    cluster
}

/// Waits up to a minute for `ready`; fails with the cluster's logs past it.
fn wait_for(cluster: &Cluster, what: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "waited a minute for {what}:\n{}",
            cluster.logs()
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn a_campaign_as_a_slurm_job_array_merges_into_the_unsharded_report() {
    let found: Vec<Option<PathBuf>> = PROGRAMS.iter().map(|p| find(p)).collect();
    if let Some(missing) = PROGRAMS.iter().zip(&found).find(|(_, f)| f.is_none()).map(|(p, _)| p) {
        println!(
            "slurm: skipped, `{missing}` is not installed (apt-get install slurm-wlm munge, as .ci/run does)"
        );
        return;
    }
    let bin = |name: &str| find(name).expect("found above");
    let cluster = cluster(&bin);
    let fixtures = repo().join("crates/aviary-cli/tests/campaign");
    let out = cluster.dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let aviary_bin = env!("CARGO_BIN_EXE_aviary");
    // As a user writes it: each task flies its share of the seeds, its report to its file.
    let wrap = format!(
        "{aviary_bin} test patrol.mission --runs {RUNS} --jobs 1 --shard $SLURM_ARRAY_TASK_ID/{SHARDS} --format json"
    );
    let mut sbatch = cluster
        .client(&bin("sbatch"))
        .args([
            "--wait",
            &format!("--array=1-{SHARDS}"),
            &format!("--chdir={}", fixtures.display()),
            &format!("--output={}/shard_%a.json", out.display()),
            &format!("--error={}/shard_%a.err", out.display()),
            "--wrap",
            &wrap,
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("sbatch");
    let code = wait_at_most(&mut sbatch, Duration::from_secs(600), "the job array");
    // Each task exits 1: some runs of the fixture fail (docs/CAMPAIGNS.md), so `sbatch
    // --wait` exits 1 too; what counts is that every shard wrote its report.
    let shards: Vec<String> =
        (1..=SHARDS).map(|i| out.join(format!("shard_{i}.json")).display().to_string()).collect();
    for (i, shard) in shards.iter().enumerate() {
        let err =
            std::fs::read_to_string(out.join(format!("shard_{}.err", i + 1))).unwrap_or_default();
        let text = std::fs::read_to_string(shard).unwrap_or_default();
        assert!(
            text.contains("\"format\": \"aviary-campaign/1\""),
            "shard {} (sbatch exited {code}): {text}{err}\n{}",
            i + 1,
            cluster.logs()
        );
    }
    let mut merge = vec!["test", "merge", "--format", "json"];
    merge.extend(shards.iter().map(String::as_str));
    let (_, merged, err) = aviary(&merge, &fixtures);
    let (_, whole, _) =
        aviary(&["test", "patrol.mission", "--runs", RUNS, "--format", "json"], &fixtures);
    assert!(!merged.is_empty(), "{err}");
    assert_eq!(merged, whole, "the merged shards are the unsharded report, byte for byte");
}
