//! The Slurm stage of `cargo xtask test`: a real single-node Slurm (Debian's slurmctld, slurmd
//! and munged, started here as plain processes with a generated slurm.conf and munge key under a
//! temporary directory) runs a small campaign as `slurm/submit.sh`'s job array and merge job;
//! the merged report must equal the unsharded campaign's byte for byte. Daemons always stopped.

use crate::bootstrap::{self, program};
use crate::monitor_mc;
use crate::shell::workspace_root;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The campaign: nominal runs, runs per fault kind, shards, seed.
const CAMPAIGN: (u64, u64, u64, u64) = (6, 1, 3, 3);

/// How long the campaign may take on the cluster before the stage fails.
const WAIT: Duration = Duration::from_secs(300);

/// The daemons this stage started; stopped (and the directory removed) when dropped.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
    children: Vec<(&'static str, Child)>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = self.command("scontrol").arg("shutdown").output();
        let deadline = Instant::now() + Duration::from_secs(10);
        for (_, child) in &mut self.children {
            while Instant::now() < deadline && matches!(child.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(100));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

impl Cluster {
    fn command(&self, name: &str) -> Command {
        let mut cmd = Command::new(program(name).unwrap_or_else(|| name.into()));
        cmd.env("SLURM_CONF", &self.conf);
        cmd
    }

    fn spawn(&mut self, name: &'static str, args: &[&str]) -> Result<(), String> {
        let log = std::fs::File::create(self.dir.join(format!("{name}.out")))
            .map_err(|e| e.to_string())?;
        let child = self
            .command(name)
            .args(args)
            .stdout(log.try_clone().map_err(|e| e.to_string())?)
            .stderr(log)
            .spawn()
            .map_err(|e| format!("starting {name}: {e}"))?;
        self.children.push((name, child));
        Ok(())
    }

    /// Waits until `ready` holds, or fails naming `what` with the daemons' output.
    fn wait_for(
        &self,
        what: &str,
        limit: Duration,
        ready: impl Fn() -> bool,
    ) -> Result<(), String> {
        let started = Instant::now();
        while !ready() {
            if started.elapsed() > limit {
                return Err(format!(
                    "{what} within {} s{}",
                    limit.as_secs(),
                    self.logs()
                ));
            }
            std::thread::sleep(Duration::from_millis(500));
        }
        Ok(())
    }

    /// The tail of every log in the directory, for a failure's message.
    fn logs(&self) -> String {
        let mut s = String::new();
        for entry in std::fs::read_dir(&self.dir).into_iter().flatten().flatten() {
            let path = entry.path();
            if path.is_file() && path.extension().is_some_and(|e| e == "out" || e == "log") {
                let text = std::fs::read_to_string(&path).unwrap_or_default();
                let tail: Vec<&str> = text.lines().rev().take(8).collect();
                let tail: Vec<&str> = tail.into_iter().rev().collect();
                s += &format!("\n--- {}\n{}", path.display(), tail.join("\n"));
            }
        }
        s
    }
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

fn hostname() -> String {
    Command::new("hostname")
        .arg("-s")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "localhost".into())
}

/// Starts munged, slurmctld and slurmd under `dir`.
fn start(dir: PathBuf) -> Result<Cluster, String> {
    use std::os::unix::fs::PermissionsExt;
    let conf = dir.join("slurm.conf");
    let mut c = Cluster {
        dir: dir.clone(),
        conf: conf.clone(),
        children: Vec::new(),
    };
    for sub in ["munge", "state", "spool"] {
        std::fs::create_dir_all(dir.join(sub)).map_err(|e| e.to_string())?;
    }
    // munged wants every directory on its socket's path executable by all.
    for d in [dir.clone(), dir.join("munge")] {
        std::fs::set_permissions(&d, std::fs::Permissions::from_mode(0o755))
            .map_err(|e| e.to_string())?;
    }
    let d = |p: &str| dir.join(p).display().to_string();
    let status = c
        .command("mungekey")
        .args(["-c", "-k", &d("munge/munge.key")])
        .status();
    if !status.is_ok_and(|s| s.success()) {
        return Err("mungekey could not create a key".into());
    }
    let socket = d("munge/munge.sock");
    let key = format!("--key-file={}", d("munge/munge.key"));
    let args = [
        format!("--socket={socket}"),
        format!("--pid-file={}", d("munge/munged.pid")),
        format!("--log-file={}", d("munge/munged.log")),
        format!("--seed-file={}", d("munge/munged.seed")),
    ];
    let mut munged: Vec<&str> = vec!["-F", &key];
    munged.extend(args.iter().map(String::as_str));
    c.spawn("munged", &munged)?;
    c.wait_for(
        "munged did not open its socket",
        Duration::from_secs(20),
        || Path::new(&socket).exists(),
    )?;
    let host = hostname();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    write(
        &conf,
        &format!(
            "ClusterName=nobacktest\nSlurmctldHost={host}(127.0.0.1)\nSlurmUser=root\nSlurmdUser=root\n\
             SlurmctldPort=16817\nSlurmdPort=16818\nAuthType=auth/munge\nCredType=cred/munge\n\
             AuthInfo=socket={socket}\nStateSaveLocation={}\nSlurmdSpoolDir={}\n\
             SlurmctldPidFile={}\nSlurmdPidFile={}\nSlurmctldLogFile={}\nSlurmdLogFile={}\n\
             ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
             JobAcctGatherType=jobacct_gather/none\nAccountingStorageType=accounting_storage/none\n\
             SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nReturnToService=2\nMpiDefault=none\n\
             NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
             PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
            d("state"),
            d("spool"),
            d("slurmctld.pid"),
            d("slurmd.pid"),
            d("slurmctld.log"),
            d("slurmd.log"),
        ),
    )?;
    c.spawn("slurmctld", &["-D", "-i"])?;
    c.spawn("slurmd", &["-D", "-N", &host])?;
    let sinfo = c.command("sinfo");
    let idle = move || {
        let mut s = Command::new(sinfo.get_program());
        s.envs(sinfo.get_envs().filter_map(|(k, v)| Some((k, v?))));
        s.args(["-h", "-o", "%T"])
            .output()
            .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
    };
    c.wait_for(
        "the node did not come up idle",
        Duration::from_secs(60),
        idle,
    )?;
    Ok(c)
}

/// Entry: the stage.
pub fn stage() -> Result<(), String> {
    bootstrap::ensure_slurm()?;
    let (runs, fault_runs, shards, seed) = CAMPAIGN;
    let started = Instant::now();
    let dir = std::env::temp_dir().join(format!("noback-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let cluster = start(dir.clone())?;
    println!(
        "single-node Slurm up in {:.1} s ({})",
        started.elapsed().as_secs_f64(),
        dir.display()
    );
    let out = dir.join("campaign");
    let exe = crate::shell::this_exe()?; // the rebuilt binary, not a deleted path
    let submitted = cluster
        .command("bash")
        .arg(workspace_root().join("slurm/submit.sh"))
        .args([runs, fault_runs, shards, seed].map(|v| v.to_string()))
        .arg(&out)
        .env("NOBACK_XTASK", &exe)
        .env("MC_MERGE_ARGS", "--no-doc")
        .env("PATH", path_with_sbin())
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("slurm/submit.sh: {e}"))?;
    let ids = String::from_utf8_lossy(&submitted.stdout)
        .trim()
        .to_string();
    if !submitted.status.success() {
        return Err(format!(
            "slurm/submit.sh failed ({}){}",
            submitted.status,
            cluster.logs()
        ));
    }
    println!(
        "submitted {shards} shards of {runs} + {fault_runs}×8 runs as array and merge jobs {ids}"
    );
    // Meanwhile the same campaign unsharded, here.
    let whole = monitor_mc::unsharded_report(seed, runs, fault_runs)?;
    let report = out.join("report.json");
    let queue_empty = || {
        cluster
            .command("squeue")
            .args(["-h", "-o", "%i"])
            .output()
            .is_ok_and(|o| o.status.success() && o.stdout.iter().all(u8::is_ascii_whitespace))
    };
    cluster.wait_for("the campaign did not finish on Slurm", WAIT, || {
        queue_empty()
    })?;
    let merged = std::fs::read_to_string(&report)
        .map_err(|e| format!("no merged report ({e}): a job failed{}", cluster.logs()))?;
    if merged != format!("{whole}\n") {
        return Err(format!(
            "the merged report differs from the unsharded one:\n{merged}\n{whole}"
        ));
    }
    println!(
        "merged report of {shards} Slurm array tasks = unsharded report, byte for byte ({} bytes) in {:.0} s",
        merged.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// PATH with `/usr/sbin` (where Debian puts the daemons) for the scripts.
fn path_with_sbin() -> String {
    let path = std::env::var("PATH").unwrap_or_default();
    format!("{path}:/usr/sbin:/usr/bin")
}
