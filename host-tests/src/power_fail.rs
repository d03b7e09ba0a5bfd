//! The trip log under power loss (`cargo xtask power-fail`): a sequence of real trip records
//! pushed into the store on [`SimFlash`], with the power cut at every step (each word
//! programmed, each page erased) in turn. After each cut the store is opened again and read:
//! every record that survives whichever way the push in flight ends must be there intact, the
//! one in flight whole or absent, nothing unreadable; then the rest are pushed and read back.
//! Past capacity the oldest records go: counted, and the newest kept.

use crate::accuracy::scene_trace;
use crate::sim_flash::SimFlash;
use noback::monitor::{Config, Flags, Inputs, Monitor};
use noback::trip_log::record;
use noback::trip_log::store::Store;
use noback::trip_log::Recorder;
use noback_twin::scene::Scene;

/// Erase page of the test's flash: 2 KB (a small part's page; the F405's 16 KB sectors only
/// make each run longer) and pages in its region.
pub const PAGE: usize = 2048;
/// Pages in the test's region.
pub const PAGES: usize = 4;
/// Inputs the test recorder keeps: small records, several to a page.
pub const RING: usize = 16;

type Flash = SimFlash<PAGE>;

fn store(flash: Flash) -> Result<Store<Flash>, String> {
    Store::new(flash, 0..(PAGES * PAGE) as u32).map_err(|e| format!("store: {e:?}"))
}

/// `count` real records: a fault scene through the monitor with a recorder, a record written
/// every 500 ticks as if the flags changed there.
pub fn sample_records(count: usize) -> Result<Vec<Vec<u8>>, String> {
    let text = "[scene]\nkind = \"reverse_load\"\nduration_s = 2.0\n[[fault]]\nkind = \"encoder_stuck\"\nat_s = 0.1\nseverity = 1.0\n";
    let scene = Scene::from_toml("power-fail", text).map_err(|e| format!("{e:?}"))?;
    let trace = scene_trace(&scene)?;
    let mut monitor = Monitor::new(Config::default()).map_err(|e| format!("{e:?}"))?;
    let mut recorder = Recorder::<RING>::new();
    let mut out = Vec::new();
    let mut before = Flags::default();
    for (k, r) in trace.rows.iter().enumerate() {
        let inputs = Inputs::new(r.current_code, r.motor_count, r.output_count, r.drive_on);
        recorder.before_step(&monitor, &inputs);
        let e = monitor.step(&inputs);
        if k % 500 == 499 && out.len() < count {
            let mut buf = [0_u8; 4096];
            out.push(
                recorder
                    .record(&mut buf, &e, before)
                    .map_err(|e| format!("{e:?}"))?
                    .to_vec(),
            );
        }
        before = e.flags;
    }
    Ok(out)
}

/// Reads every record back: the indices (into `records`) of the ones found, and how many
/// items were unreadable or matched no record.
fn read_back(store: &mut Store<Flash>, records: &[Vec<u8>]) -> Result<(Vec<usize>, usize), String> {
    let mut found = Vec::new();
    let mut corrupt = 0;
    let mut buf = vec![0_u8; PAGE];
    store
        .for_each(&mut buf, |item| {
            match (record::decode(item), records.iter().position(|r| r == item)) {
                (Ok(_), Some(i)) => found.push(i),
                _ => corrupt += 1,
            }
        })
        .map_err(|e| format!("reading back: {e:?}"))?;
    Ok((found, corrupt))
}

/// What the runs found.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figures {
    /// Power cuts tried (one at every step of the sequence).
    pub cuts: u64,
    /// Records that should have survived the cut and were not read back.
    pub records_lost: usize,
    /// Items read back that did not decode or matched no record.
    pub corrupt_reads: usize,
    /// Cuts after which the record in flight was read back whole / was absent.
    pub in_flight_whole: u64,
    pub in_flight_absent: u64,
    /// Cuts after which the store did not take the remaining records or lost the newest.
    pub stopped_working: u64,
    /// Records pushed in the overflow run, kept, and dropped (the oldest).
    pub pushed: usize,
    pub kept: usize,
    pub dropped: usize,
    /// Record size (bytes, largest) and flash steps for the whole sequence.
    pub record_bytes: usize,
    pub steps: u64,
    /// Words programmed and pages erased per record, over the uncut sequence.
    pub words_per_record: f64,
    pub erases_per_record: f64,
}

/// The kept records after pushing `records[..n]` with no cut.
fn reference(records: &[Vec<u8>], n: usize) -> Result<Vec<usize>, String> {
    let mut s = store(Flash::new(PAGES))?;
    for r in &records[..n] {
        s.push(r).map_err(|e| format!("{e:?}"))?;
    }
    Ok(read_back(&mut s, records)?.0)
}

/// Runs the sequence with a cut at every step, then the overflow run.
pub fn run(records: &[Vec<u8>]) -> Result<Figures, String> {
    let mut f = Figures::default();
    let n = records.len();
    let refs: Vec<Vec<usize>> = (0..=n)
        .map(|k| reference(records, k))
        .collect::<Result<_, _>>()?;
    let mut whole = store(Flash::new(PAGES))?;
    for r in records {
        whole.push(r).map_err(|e| format!("{e:?}"))?;
    }
    let (kept, _) = read_back(&mut whole, records)?;
    let flash = whole.into_flash();
    (f.steps, f.pushed, f.kept) = (flash.steps, n, kept.len());
    f.dropped = n - kept.len();
    f.record_bytes = records.iter().map(Vec::len).max().unwrap_or(0);
    f.words_per_record = flash.words_written as f64 / n.max(1) as f64;
    f.erases_per_record = flash.erases as f64 / n.max(1) as f64;
    for cut in 0..f.steps {
        f.cuts += 1;
        let mut flash = Flash::new(PAGES);
        flash.cut_at = Some(cut);
        let mut s = store(flash)?;
        let done = records.iter().take_while(|r| s.push(r).is_ok()).count();
        let mut flash = s.into_flash();
        flash.power_on();
        let mut s = store(flash)?;
        let (found, corrupt) = read_back(&mut s, records)?;
        f.corrupt_reads += corrupt;
        // Survivors either way the push in flight ends.
        let (a, b) = (&refs[done], &refs[(done + 1).min(n)]);
        f.records_lost += a
            .iter()
            .filter(|i| b.contains(i) && !found.contains(i))
            .count();
        if found.contains(&done) {
            f.in_flight_whole += 1;
        } else {
            f.in_flight_absent += 1;
        }
        // It keeps working: the records after the one in flight go in (the firmware lost that
        // one with its RAM) and the newest come back in order.
        let rest = records.get(done + 1..).unwrap_or(&[]);
        let rest_ok = rest.iter().all(|r| s.push(r).is_ok());
        let (after, corrupt) = read_back(&mut s, records)?;
        f.corrupt_reads += corrupt;
        let newest = if rest.is_empty() && !found.contains(&done) {
            done.checked_sub(1)
        } else {
            Some(n - 1)
        };
        let newest_in_order =
            after.last().copied() == newest && after.windows(2).all(|w| w[0] < w[1]);
        if !rest_ok || !newest_in_order {
            f.stopped_working += 1;
        }
    }
    Ok(f)
}
