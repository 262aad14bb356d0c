//! The campaign's machinery: the context a call draws its arguments from ([`Ctx`]), the
//! classification of its result ([`Verdict`]), the runner with its watchdog, shrinking of
//! findings to a minimal reproducer printed as Rust, and the report.

use crate::values::{self, Kind, Rng};
use lagrange_core::{Error, Real};
use std::cell::RefCell;
use std::fmt::Write as _;
use std::panic::{self, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// What one call came to.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// `Ok`, with every number in the result finite.
    Ok,
    /// A specific error (naming one of the call's own parameters, if any).
    Error(Error),
    /// A panic, with its message.
    Panic(String),
    /// The call did not return within the deadline.
    Hang,
    /// `Ok` with a NaN or an infinity in the result: what held it.
    Silent(String),
    /// `InvalidParameter` naming a parameter the call does not have.
    WrongName(String),
    /// A stateful API returned an error and its observable state changed.
    Changed(String),
    /// Two ways to ask the same thing disagreed (a step and a one-step run).
    Inconsistent(String),
    /// `Ok` with a result that breaks what the docs promise of it (a contact ended below the
    /// floor, an impact gained energy, a step that took no step).
    Broken(String),
}

/// The classes of [`Verdict`], for counting.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Ok,
    Error,
    Panic,
    Hang,
    Silent,
    Wrong,
    Changed,
    Inconsistent,
    Broken,
}

/// Every class, in the columns' order.
pub const CLASSES: [Class; 9] = [
    Class::Ok,
    Class::Error,
    Class::Panic,
    Class::Hang,
    Class::Silent,
    Class::Wrong,
    Class::Changed,
    Class::Inconsistent,
    Class::Broken,
];

impl Class {
    /// The column heading.
    fn heading(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Error => "error",
            Self::Panic => "panic",
            Self::Hang => "hang",
            Self::Silent => "silent",
            Self::Wrong => "wrong",
            Self::Changed => "changed",
            Self::Inconsistent => "incons.",
            Self::Broken => "broken",
        }
    }

    /// True for the classes that are findings.
    pub fn is_finding(self) -> bool {
        !matches!(self, Self::Ok | Self::Error)
    }
}

impl Verdict {
    /// The class.
    pub fn class(&self) -> Class {
        match self {
            Self::Ok => Class::Ok,
            Self::Error(_) => Class::Error,
            Self::Panic(_) => Class::Panic,
            Self::Hang => Class::Hang,
            Self::Silent(_) => Class::Silent,
            Self::WrongName(_) => Class::Wrong,
            Self::Changed(_) => Class::Changed,
            Self::Inconsistent(_) => Class::Inconsistent,
            Self::Broken(_) => Class::Broken,
        }
    }
}

/// How a drawn slot may be simplified when shrinking.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    /// A float of the call's scalar type (`f32` when the flag is set).
    Float(bool),
    /// A count.
    Count,
    /// A structural choice: kept as drawn.
    Pick,
}

/// The context of one call: its arguments, drawn from the call's own generator or replayed
/// (when shrinking), and the Rust lines of its reproducer (when recording).
pub struct Ctx {
    rng: Rng,
    /// How much more often than usual this call draws nasty values.
    hostility: f64,
    replay: Vec<f64>,
    used: Vec<f64>,
    slots: Vec<Slot>,
    script: Option<Arc<Mutex<Vec<String>>>>,
}

impl Ctx {
    fn new(mut rng: Rng, replay: Vec<f64>, script: Option<Arc<Mutex<Vec<String>>>>) -> Self {
        let hostility = if rng.chance(0.25) { 4.0 } else { 1.0 };
        Self {
            rng,
            hostility,
            replay,
            used: Vec::new(),
            slots: Vec::new(),
            script,
        }
    }

    /// The next slot: drawn (the generator always advances, so that replaying a changed
    /// value leaves the later draws as they were), or replayed.
    fn slot(&mut self, drawn: f64, slot: Slot) -> f64 {
        let v = self.replay.get(self.used.len()).copied().unwrap_or(drawn);
        self.used.push(v);
        self.slots.push(slot);
        v
    }

    /// A value of `T` for `kind`.
    pub fn value<T: Real>(&mut self, kind: Kind) -> T {
        let drawn = values::draw::<T>(kind, &mut self.rng, self.hostility);
        let single = T::EPSILON.to_f64() > 1e-10;
        T::from_f64(self.slot(drawn, Slot::Float(single)))
    }

    /// `K` values of `T` for `kind`.
    pub fn values<T: Real, const K: usize>(&mut self, kind: Kind) -> [T; K] {
        core::array::from_fn(|_| self.value(kind))
    }

    /// A value of `T` uniform in `[lo, hi)`: ordinary input, drawn to reach states (a body
    /// in flight, a pose within its limits) rather than to be hostile.
    pub fn uniform<T: Real>(&mut self, lo: f64, hi: f64) -> T {
        let drawn = lo + (hi - lo) * self.rng.unit();
        let single = T::EPSILON.to_f64() > 1e-10;
        T::from_f64(self.slot(drawn, Slot::Float(single)))
    }

    /// A count.
    pub fn count(&mut self) -> u64 {
        let drawn = values::count(&mut self.rng) as f64;
        // Counts above 2^53 are rounded in the record, and replayed as u64::MAX at most.
        let v = self.slot(drawn, Slot::Count);
        if v >= u64::MAX as f64 {
            u64::MAX
        } else {
            v as u64
        }
    }

    /// One of `n` choices.
    pub fn pick(&mut self, n: usize) -> usize {
        let drawn = self.rng.below(n as u64) as f64;
        (self.slot(drawn, Slot::Pick) as usize).min(n.saturating_sub(1))
    }

    /// A line of the reproducer, written before the call it shows (so that a hang's
    /// reproducer ends with the call that hung).
    pub fn say(&self, line: impl FnOnce() -> String) {
        if let Some(script) = &self.script {
            if let Ok(mut s) = script.lock() {
                s.push(line());
            }
        }
    }
}

/// `x` as a Rust literal of `T` (`1.5_f64`, `f32::NAN`, `-f64::MAX`).
pub fn lit<T: Real>(x: T) -> String {
    let ty = ty::<T>();
    let v = x.to_f64();
    let max = T::MAX.to_f64();
    let named = |n: &str| format!("{ty}::{n}");
    if v.is_nan() {
        named("NAN")
    } else if v == f64::INFINITY {
        named("INFINITY")
    } else if v == f64::NEG_INFINITY {
        named("NEG_INFINITY")
    } else if v == max {
        named("MAX")
    } else if v == -max {
        format!("-{}", named("MAX"))
    } else if v == T::MIN_POSITIVE.to_f64() {
        named("MIN_POSITIVE")
    } else {
        format!("{x:?}_{ty}")
    }
}

/// `[a, b, ...]` of literals.
pub fn lits<T: Real>(xs: &[T]) -> String {
    let parts: Vec<String> = xs.iter().map(|&x| lit(x)).collect();
    format!("[{}]", parts.join(", "))
}

/// The name of `T`.
pub fn ty<T: Real>() -> &'static str {
    if T::EPSILON.to_f64() > 1e-10 {
        "f32"
    } else {
        "f64"
    }
}

/// Writes a reproducer line: `say!(ctx, "let p = X::new({});", lit(a))`.
#[macro_export]
macro_rules! say {
    ($ctx:expr, $($fmt:tt)*) => {
        $ctx.say(|| format!($($fmt)*))
    };
}

/// One entry point of the campaign: a name, a share of the calls, and the call itself.
pub struct Entry {
    pub name: String,
    pub weight: f64,
    pub run: fn(&mut Ctx) -> Verdict,
}

/// A family of entry points, run on one worker thread and reported in one table.
pub struct Family {
    pub name: &'static str,
    pub entries: Vec<Entry>,
}

/// Makes the `f32` and `f64` entries of a case generic over the scalar:
/// `entries!(v, weight, "name", case)`.
#[macro_export]
macro_rules! entries {
    ($v:expr, $weight:expr, $name:expr, $case:ident) => {
        $v.push($crate::harness::Entry {
            name: format!("{} f64", $name),
            weight: $weight,
            run: $case::<f64>,
        });
        $v.push($crate::harness::Entry {
            name: format!("{} f32", $name),
            weight: $weight,
            run: $case::<f32>,
        });
    };
}

/// The campaign's settings.
#[derive(Debug, Clone)]
pub struct Config {
    /// The seed every call's generator derives from.
    pub seed: u64,
    /// How many calls in all, shared among the entry points by weight.
    pub calls: u64,
    /// A call running longer than this is a hang.
    pub deadline: Duration,
    /// Only families whose name contains this.
    pub only: Option<String>,
    /// Reproducers printed per entry point and class.
    pub reproducers: usize,
}

/// Counts per class of one entry point, and its slowest call.
#[derive(Debug, Clone, Default)]
pub struct Counts {
    pub by_class: [u64; 9],
    /// The longest a call took, and which.
    pub slowest: (Duration, u64),
}

impl Counts {
    fn add(&mut self, c: Class) {
        if let Some(i) = CLASSES.iter().position(|&x| x == c) {
            self.by_class[i] += 1;
        }
    }
    /// Calls counted in class `c`.
    pub fn get(&self, c: Class) -> u64 {
        CLASSES
            .iter()
            .position(|&x| x == c)
            .map_or(0, |i| self.by_class[i])
    }
    /// Every call counted.
    pub fn total(&self) -> u64 {
        self.by_class.iter().sum()
    }
    fn merge(&mut self, o: &Counts) {
        for (a, b) in self.by_class.iter_mut().zip(o.by_class) {
            *a += b;
        }
        if o.slowest.0 > self.slowest.0 {
            self.slowest = o.slowest;
        }
    }
}

/// A finding: where, what, and its reproducer.
#[derive(Debug, Clone)]
pub struct Finding {
    pub entry: String,
    pub index: u64,
    pub verdict: Verdict,
    pub reproducer: String,
}

/// What the worker and the watchdog share.
struct Shared {
    counts: Mutex<Vec<Counts>>,
    findings: Mutex<Vec<Finding>>,
    /// The entry and call in flight.
    current: Mutex<(usize, u64)>,
    /// When the call in flight started, in ns since the run started (0 when idle).
    started: AtomicU64,
    /// The worker thread's entry under `/proc/self/task` (Linux), for its CPU time.
    task: Mutex<Option<String>>,
    done: AtomicBool,
}

/// CPU time the thread `task` (a `/proc/self/task` entry) has used, s: its user and system
/// clock ticks (`utime`, `stime`, fields 14 and 15 of its `stat`), at the 100 ticks a second
/// Linux reports them in. `None` where there is no such file (not Linux).
fn cpu_seconds(task: &str) -> Option<f64> {
    let stat = std::fs::read_to_string(format!("/proc/self/task/{task}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count after it.
    let after = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<f64>().ok();
    Some((ticks(11)? + ticks(12)?) / 100.0)
}

/// A call is a hang when it has run for the deadline and then used the deadline again in CPU
/// time. The second half makes the verdict independent of the machine's load: a call that a
/// busy machine (or the campaign's other families, one thread each) starves of the CPU runs
/// longer in wall time but not in CPU time, while a loop that never ends uses all it gets.
/// Without `/proc` (not Linux) the wall time alone decides.
struct HangWatch {
    /// The call watched and the worker's CPU time when its wall time passed the deadline.
    over: Option<((usize, u64), f64)>,
}

impl HangWatch {
    /// Whether call `current`, running for `wall`, hangs.
    fn hangs(
        &mut self,
        current: (usize, u64),
        wall: Duration,
        deadline: Duration,
        task: Option<&str>,
    ) -> bool {
        if wall <= deadline {
            return false;
        }
        let Some(cpu) = task.and_then(cpu_seconds) else {
            return true;
        };
        match self.over {
            Some((call, from)) if call == current => cpu - from > deadline.as_secs_f64(),
            _ => {
                self.over = Some((current, cpu));
                false
            }
        }
    }
}

thread_local! {
    /// The message of the last panic on this thread (the hook prints nothing).
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Installs a panic hook that keeps the message instead of printing it.
pub fn quiet_panics() {
    panic::set_hook(Box::new(|info| {
        let msg = info.to_string();
        LAST_PANIC.with(|p| *p.borrow_mut() = msg);
    }));
}

/// Runs `run` under `catch_unwind`.
fn guarded(run: fn(&mut Ctx) -> Verdict, ctx: &mut Ctx) -> Verdict {
    match panic::catch_unwind(AssertUnwindSafe(|| run(ctx))) {
        Ok(v) => v,
        Err(_) => Verdict::Panic(LAST_PANIC.with(|p| p.borrow().clone())),
    }
}

/// The reproducer of call `index` of `entry` with the arguments `replay`: the case run again
/// in recording mode on a thread of its own, given `wait` to finish (a hang's script stops
/// at the call that hangs; that thread is then left behind).
fn reproducer(
    seed: u64,
    entry: &Entry,
    entry_id: u64,
    index: u64,
    replay: Vec<f64>,
    wait: Duration,
) -> String {
    let script = Arc::new(Mutex::new(Vec::new()));
    let record = Arc::clone(&script);
    let run = entry.run;
    let rng = Rng::for_call(seed, entry_id, index);
    let handle = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(move || {
            let mut ctx = Ctx::new(rng, replay, Some(record));
            guarded(run, &mut ctx)
        });
    let start = Instant::now();
    if let Ok(h) = &handle {
        while !h.is_finished() && start.elapsed() < wait {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
    let lines = script.lock().map(|s| s.clone()).unwrap_or_default();
    let mut out = String::new();
    for l in lines {
        let _ = writeln!(out, "    {l}");
    }
    out
}

/// Shrinks the arguments of a call with verdict class `class` towards simple values (1, 0,
/// 0.5, 2, 10), slot by slot, keeping each change that keeps the class.
fn shrink(entry: &Entry, rng: &Rng, used: Vec<f64>, slots: &[Slot], class: Class) -> Vec<f64> {
    let mut best = used;
    for _ in 0..4 {
        let mut changed = false;
        for i in 0..best.len() {
            let candidates: &[f64] = match slots.get(i) {
                Some(Slot::Float(_)) => &[1.0, 0.0, 0.5, 2.0, 10.0, -1.0],
                Some(Slot::Count) => &[1.0, 0.0, 2.0, 10.0],
                _ => &[],
            };
            let current = best[i];
            let rank = |x: f64| candidates.iter().position(|&c| c.to_bits() == x.to_bits());
            for &c in candidates {
                let better = match rank(current) {
                    Some(r) => rank(c).is_some_and(|rc| rc < r),
                    None => true,
                };
                if !better {
                    continue;
                }
                let mut trial = best.clone();
                trial[i] = c;
                let mut ctx = Ctx::new(rng.clone(), trial.clone(), None);
                if guarded(entry.run, &mut ctx).class() == class {
                    best = trial;
                    changed = true;
                    break;
                }
            }
        }
        if !changed {
            break;
        }
    }
    best
}

/// Calls per entry point: `calls` shared by weight, at least one each.
fn shares(families: &[Family], calls: u64) -> Vec<Vec<u64>> {
    let total: f64 = families
        .iter()
        .flat_map(|f| f.entries.iter().map(|e| e.weight))
        .sum();
    families
        .iter()
        .map(|f| {
            f.entries
                .iter()
                .map(|e| ((calls as f64 * e.weight / total).ceil() as u64).max(1))
                .collect()
        })
        .collect()
}

/// The outcome of a family.
pub struct FamilyReport {
    pub name: &'static str,
    pub entries: Vec<(String, Counts)>,
    pub findings: Vec<Finding>,
    pub hung: bool,
}

/// Runs every family, one worker thread at a time under the watchdog.
pub fn run(families: Vec<Family>, cfg: &Config) -> Vec<FamilyReport> {
    let shares = shares(&families, cfg.calls);
    let mut reports = Vec::new();
    let mut entry_base = 0u64;
    let families: Vec<Arc<Family>> = families.into_iter().map(Arc::new).collect();
    for (fi, family) in families.iter().enumerate() {
        let base = entry_base;
        entry_base += family.entries.len() as u64;
        if cfg
            .only
            .as_ref()
            .is_some_and(|only| !family.name.contains(only.as_str()))
        {
            continue;
        }
        reports.push(run_family(Arc::clone(family), &shares[fi], base, cfg));
    }
    reports
}

/// One family on a worker thread, watched.
fn run_family(family: Arc<Family>, share: &[u64], base: u64, cfg: &Config) -> FamilyReport {
    let shared = Arc::new(Shared {
        counts: Mutex::new(vec![Counts::default(); family.entries.len()]),
        findings: Mutex::new(Vec::new()),
        current: Mutex::new((0, 0)),
        started: AtomicU64::new(0),
        task: Mutex::new(None),
        done: AtomicBool::new(false),
    });
    let epoch = Instant::now();
    let worker = {
        let (family, shared, share) = (Arc::clone(&family), Arc::clone(&shared), share.to_vec());
        let (seed, keep) = (cfg.seed, cfg.reproducers);
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn(move || work(&family, &shared, &share, base, seed, keep, epoch))
    };
    let mut hung = false;
    let mut watch = HangWatch { over: None };
    loop {
        std::thread::sleep(Duration::from_millis(2));
        if shared.done.load(Ordering::Acquire) {
            break;
        }
        let started = shared.started.load(Ordering::Acquire);
        let now = epoch.elapsed().as_nanos() as u64;
        let wall = Duration::from_nanos(now.saturating_sub(started));
        if started == 0 || wall <= cfg.deadline {
            continue;
        }
        let (ei, index) = shared.current.lock().map(|c| *c).unwrap_or((0, 0));
        let task = shared.task.lock().ok().and_then(|t| t.clone());
        if watch.hangs((ei, index), wall, cfg.deadline, task.as_deref()) {
            // A hang: count it, record its reproducer, and give up on this family (the
            // worker cannot be stopped; it is left behind).
            hung = true;
            if let Some(entry) = family.entries.get(ei) {
                let repro = reproducer(
                    cfg.seed,
                    entry,
                    base + ei as u64,
                    index,
                    Vec::new(),
                    cfg.deadline.min(Duration::from_secs(2)),
                );
                if let Ok(mut c) = shared.counts.lock() {
                    c[ei].add(Class::Hang);
                }
                if let Ok(mut f) = shared.findings.lock() {
                    f.push(Finding {
                        entry: entry.name.clone(),
                        index,
                        verdict: Verdict::Hang,
                        reproducer: repro,
                    });
                }
            }
            break;
        }
    }
    if !hung {
        if let Ok(h) = worker {
            let _ = h.join();
        }
    }
    let counts = shared.counts.lock().map(|c| c.clone()).unwrap_or_default();
    let findings = shared
        .findings
        .lock()
        .map(|f| f.clone())
        .unwrap_or_default();
    FamilyReport {
        name: family.name,
        entries: family
            .entries
            .iter()
            .map(|e| e.name.clone())
            .zip(counts)
            .collect(),
        findings,
        hung,
    }
}

/// The worker: every call of every entry point of `family`.
fn work(
    family: &Family,
    shared: &Shared,
    share: &[u64],
    base: u64,
    seed: u64,
    keep: usize,
    epoch: Instant,
) {
    // This thread's entry under /proc/self/task, "PID/task/TID" read from /proc/thread-self.
    if let Ok(mut task) = shared.task.lock() {
        *task = std::fs::read_link("/proc/thread-self")
            .ok()
            .and_then(|p| Some(p.file_name()?.to_string_lossy().into_owned()));
    }
    for (ei, entry) in family.entries.iter().enumerate() {
        let entry_id = base + ei as u64;
        let mut kept = [0usize; 9];
        let mut local = Counts::default();
        for index in 0..share[ei] {
            if let Ok(mut c) = shared.current.lock() {
                *c = (ei, index);
            }
            shared.started.store(
                (epoch.elapsed().as_nanos() as u64).max(1),
                Ordering::Release,
            );
            let rng = Rng::for_call(seed, entry_id, index);
            let mut ctx = Ctx::new(rng.clone(), Vec::new(), None);
            let began = Instant::now();
            let verdict = guarded(entry.run, &mut ctx);
            let took = began.elapsed();
            if took > local.slowest.0 {
                local.slowest = (took, index);
            }
            let class = verdict.class();
            local.add(class);
            if class.is_finding() {
                let ci = CLASSES.iter().position(|&c| c == class).unwrap_or(0);
                if kept[ci] < keep {
                    kept[ci] += 1;
                    let small = shrink(entry, &rng, ctx.used.clone(), &ctx.slots, class);
                    let mut again = Ctx::new(rng.clone(), small.clone(), None);
                    let shrunk = guarded(entry.run, &mut again);
                    let repro =
                        reproducer(seed, entry, entry_id, index, small, Duration::from_secs(5));
                    if let Ok(mut f) = shared.findings.lock() {
                        f.push(Finding {
                            entry: entry.name.clone(),
                            index,
                            verdict: shrunk,
                            reproducer: repro,
                        });
                    }
                }
            }
            shared.started.store(0, Ordering::Release);
            // Publish the counts now and then, so that a hang later keeps them.
            if index % 256 == 255 || index + 1 == share[ei] {
                if let Ok(mut c) = shared.counts.lock() {
                    c[ei].merge(&local);
                }
                local = Counts::default();
            }
        }
    }
    shared.done.store(true, Ordering::Release);
}

/// Prints the table of each family, the findings with their reproducers, and the totals;
/// returns the totals per class.
pub fn report(reports: &[FamilyReport], cfg: &Config) -> Counts {
    let mut all = Counts::default();
    for r in reports {
        let width = r
            .entries
            .iter()
            .map(|(n, _)| n.len())
            .max()
            .unwrap_or(10)
            .max(10);
        println!();
        println!(
            "family {}{}",
            r.name,
            if r.hung { " (stopped at a hang)" } else { "" }
        );
        let mut head = format!("  {:<width$} {:>10}", "entry point", "calls");
        for c in CLASSES {
            let _ = write!(head, " {:>9}", c.heading());
        }
        let _ = write!(head, " {:>12}", "slowest ms");
        println!("{head}");
        let mut fam = Counts::default();
        for (name, counts) in &r.entries {
            let mut row = format!("  {:<width$} {:>10}", name, counts.total());
            for c in CLASSES {
                let _ = write!(row, " {:>9}", counts.get(c));
            }
            let _ = write!(row, " {:>12.3}", counts.slowest.0.as_secs_f64() * 1e3);
            println!("{row}");
            fam.merge(counts);
        }
        let mut row = format!("  {:<width$} {:>10}", "total", fam.total());
        for c in CLASSES {
            let _ = write!(row, " {:>9}", fam.get(c));
        }
        let _ = write!(row, " {:>12.3}", fam.slowest.0.as_secs_f64() * 1e3);
        println!("{row}");
        all.merge(&fam);
    }
    let findings: Vec<&Finding> = reports.iter().flat_map(|r| r.findings.iter()).collect();
    if !findings.is_empty() {
        println!();
        println!("findings (seed {}, shrunk):", cfg.seed);
        for f in findings {
            println!("- {} call {}: {:?}", f.entry, f.index, f.verdict);
            print!("{}", f.reproducer);
        }
    }
    println!();
    println!(
        "{} state changed on error, {} inconsistent, {} broken promises",
        all.get(Class::Changed),
        all.get(Class::Inconsistent),
        all.get(Class::Broken)
    );
    println!(
        "{} calls, {} panics, {} hangs, {} silent non-finite, {} wrong parameter",
        all.total(),
        all.get(Class::Panic),
        all.get(Class::Hang),
        all.get(Class::Silent),
        all.get(Class::Wrong)
    );
    all
}
