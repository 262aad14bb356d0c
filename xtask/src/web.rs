//! `cargo xtask web`: the interactive page, the library compiled to WebAssembly.
//!
//! 1. Installs the `wasm32-unknown-unknown` target with rustup when it is missing.
//! 2. Builds `web/` (crate `lagrange-web`, plain C ABI exports) for it in the `web` profile,
//!    twice: without and with WebAssembly SIMD (`simd128`, under which a scene's banks in
//!    lanes step side by side); the page loads the second where the browser has SIMD.
//! 3. Writes the static site to `target/lagrange-web/`: `web/site/*` and the two `.wasm`; no
//!    CDN, no network at run time.
//! 4. Serves it on 127.0.0.1 and prints the URL (`--no-serve`: stops after the build).
//!
//! `--test` drives the page in headless Chromium (Debian's `chromium`, installed by apt-get
//! when missing) over the DevTools protocol ([`crate::cdp`]) and checks that it loads without
//! console errors, that frames advance, that it loaded the SIMD module, that the scripted
//! scenario's words and digest and the world's (three balls and a crate in a box), from the
//! SIMD module and again from the scalar one (the page loaded with `?scalar`), equal the
//! host's (x86_64, computed here) and the firmware's (under QEMU, `crate::qemu`), that the
//! sandbox's scripted pile (boxes, balls, pendulums, a chain and ragdolls in one world, a
//! ragdoll and a box thrown into it; each step timed, the slowest printed as a figure) ends
//! with the host's digest and never found more contact points than the world's cap, and that bad input (a dt of 0 or NaN, an absurd throw) shows the
//! library's error, resets the instance and leaves every drawn value finite. It saves
//! `target/lagrange-web/screenshot.png`.
//!
//! The test holds the module back for ten seconds ([`WASM_HOLD`]), as a loaded machine does
//! when it compiles it on a first start: the page must answer "not ready" until it is
//! instantiated, and the test retries until it is. No check waits for a fixed wall time:
//! each waits for frames drawn or simulated time, and the deadlines only turn a hang into a
//! failure, so that a busy machine makes the test slower, never red.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use lagrange_cases::{scripted, world_in_a_box, Outcome, CASES, STEPS};

use crate::cdp::{base64, Browser, Evaluated, Json};
use crate::cmd;
use crate::cross;
use crate::qemu;
use crate::tools::AptTool;

/// The WebAssembly target.
const WASM: &str = "wasm32-unknown-unknown";

/// The browser, from Debian's package of the same name.
pub(crate) const CHROMIUM: AptTool = AptTool {
    program: "chromium",
    package: "chromium",
};

/// The port `cargo xtask web` serves on when it is free (else any free one).
const PORT: u16 = 8018;

/// The lockstep case the page's scenario is, by precision.
const SCENE_CASE: &str = "scene (sleep, wake)";

/// The lockstep case the page's world is (`f32`).
const WORLD_CASE: &str = "world: 3 balls and a crate in a box";

/// The host's run of a lockstep case for a number of frames.
type HostRun = fn(u32) -> Result<Outcome, lagrange_core::Error>;

/// The page's scenario lines (its key in the page's state, the lockstep case and precision,
/// the host's run of it): the scripted scene in `f32` and `f64`, and the world.
const SCENARIOS: [(&str, &str, &str, HostRun); 3] = [
    ("f32", SCENE_CASE, "f32", scripted::<f32>),
    ("f64", SCENE_CASE, "f64", scripted::<f64>),
    ("world", WORLD_CASE, "f32", world_in_a_box),
];

/// `cargo xtask web [--no-serve | --test]`.
pub fn run(args: &[String]) -> Result<(), String> {
    let site = build()?;
    if args.iter().any(|a| a == "--test") {
        test(&site)
    } else if args.iter().any(|a| a == "--no-serve") {
        println!("xtask web: site written to {}", site.display());
        Ok(())
    } else {
        let listener = TcpListener::bind(("127.0.0.1", PORT))
            .or_else(|_| TcpListener::bind(("127.0.0.1", 0)))
            .map_err(|e| format!("could not listen on 127.0.0.1: {e}"))?;
        let port = listener.local_addr().map_err(|e| e.to_string())?.port();
        println!(
            "xtask web: serving {} at http://127.0.0.1:{port}/ (Ctrl-C stops)",
            site.display()
        );
        serve(&listener, &site, Duration::ZERO);
        Ok(())
    }
}

/// The page's two modules: the scalar one every browser runs, and one built with WebAssembly
/// SIMD (`simd128`), where lanes map onto 128-bit vectors and a scene's banks in lanes step
/// their instances side by side ([`VECTOR_UNIT`]), which the page loads where the browser
/// validates a SIMD instruction. Each in a target directory of its own (their flags differ,
/// and sharing one would rebuild each in turn): file, rustflags, directory under `target/`
/// (none: `target/` itself).
///
/// [`VECTOR_UNIT`]: lagrange_core::VECTOR_UNIT
const MODULES: [(&str, &str, &str); 2] = [
    ("lagrange_web.wasm", "", ""),
    (
        "lagrange_web_simd128.wasm",
        r#"target.wasm32-unknown-unknown.rustflags=["-C","target-feature=+simd128"]"#,
        "web-simd128",
    ),
];

/// Builds the two modules and writes the site; its directory.
fn build() -> Result<PathBuf, String> {
    let clock = Instant::now();
    cross::ensure_rustup_target(WASM)?;
    let root = cmd::project_root();
    let target = root.join("target");
    let site = target.join("lagrange-web");
    std::fs::create_dir_all(&site).map_err(|e| format!("{}: {e}", site.display()))?;
    let copy = |from: &Path, to: &Path| {
        std::fs::copy(from, to)
            .map(|_| ())
            .map_err(|e| format!("copying {} to {}: {e}", from.display(), to.display()))
    };
    let mut sizes = Vec::new();
    for (file, flags, dir) in MODULES {
        let dir = if dir.is_empty() {
            target.clone()
        } else {
            target.join(dir)
        };
        let mut build = cmd::cargo();
        build.args([
            "build",
            "--quiet",
            "-p",
            "lagrange-web",
            "--lib",
            "--target",
            WASM,
        ]);
        if !flags.is_empty() {
            build.args(["--config", flags]);
        }
        build.args(["--profile", "web", "--target-dir"]).arg(&dir);
        cmd::run(&mut build)?;
        let wasm = dir.join(WASM).join("web").join("lagrange_web.wasm");
        copy(&wasm, &site.join(file))?;
        let size = std::fs::metadata(site.join(file)).map_or(0, |m| m.len());
        sizes.push(format!("{file} {} KiB", size / 1024));
    }
    let sources = root.join("web").join("site");
    let entries = std::fs::read_dir(&sources).map_err(|e| format!("{}: {e}", sources.display()))?;
    for entry in entries.flatten() {
        copy(&entry.path(), &site.join(entry.file_name()))?;
    }
    println!(
        "xtask web: built in {:.0} s: {} ({})",
        clock.elapsed().as_secs_f64(),
        site.display(),
        sizes.join(", ")
    );
    Ok(site)
}

/// Serves `site` on `listener` until the process ends, one thread per connection, holding
/// the WebAssembly module back for `hold` before it answers (the test's slow first load).
fn serve(listener: &TcpListener, site: &Path, hold: Duration) {
    for stream in listener.incoming().flatten() {
        let site = site.to_path_buf();
        std::thread::spawn(move || {
            let _ = respond(stream, &site, hold);
        });
    }
}

/// Answers one GET: a file of the site by name, else 404; the module after `hold`.
fn respond(mut stream: TcpStream, site: &Path, hold: Duration) -> std::io::Result<()> {
    stream.set_read_timeout(Some(Duration::from_secs(10)))?;
    let mut request = Vec::new();
    let mut buf = [0; 4096];
    while !request.windows(4).any(|w| w == b"\r\n\r\n") && request.len() < 65536 {
        let n = stream.read(&mut buf)?;
        if n == 0 {
            break;
        }
        request.extend_from_slice(&buf[..n]);
    }
    let request = String::from_utf8_lossy(&request);
    let path = request.split_whitespace().nth(1).unwrap_or("/");
    let name = path.split('?').next().unwrap_or("").trim_start_matches('/');
    let name = if name.is_empty() { "index.html" } else { name };
    let safe = name
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b))
        && !name.starts_with('.');
    let body = if safe {
        std::fs::read(site.join(name)).ok()
    } else {
        None
    };
    let kind = match name.rsplit('.').next() {
        Some("html") => "text/html; charset=utf-8",
        Some("js") => "text/javascript; charset=utf-8",
        Some("css") => "text/css; charset=utf-8",
        Some("wasm") => "application/wasm",
        Some("png") => "image/png",
        _ => "application/octet-stream",
    };
    if name.ends_with(".wasm") {
        std::thread::sleep(hold);
    }
    let (status, kind, body) = match body {
        Some(body) => ("200 OK", kind, body),
        None => ("404 Not Found", "text/plain", b"not found".to_vec()),
    };
    write!(
        stream,
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: \
         no-store\r\nConnection: close\r\n\r\n",
        body.len()
    )?;
    stream.write_all(&body)
}

/// FNV-1a over 64-bit words: the page's digest (`lagrange_web::scenario::digest`).
fn digest(words: &[u64]) -> u64 {
    words.iter().fold(0xcbf2_9ce4_8422_2325, |hash, &w| {
        (hash ^ w).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The page's scenario line `"f32 frames=1000 words=<hex>,... digest=<hex>"`: its words
/// and digest.
fn parse_scenario(line: &str) -> Result<(Vec<u64>, u64), String> {
    let bad = || format!("unexpected scenario line from the page: {line:?}");
    let mut words = None;
    let mut shown = None;
    for field in line.split_whitespace() {
        if let Some(list) = field.strip_prefix("words=") {
            let parsed: Result<Vec<u64>, _> = list
                .split(',')
                .map(|w| u64::from_str_radix(w, 16))
                .collect();
            words = Some(parsed.map_err(|_| bad())?);
        } else if let Some(hex) = field.strip_prefix("digest=") {
            shown = Some(u64::from_str_radix(hex, 16).map_err(|_| bad())?);
        }
    }
    words.zip(shown).ok_or_else(bad)
}

/// Serves the site, drives the page in headless Chromium, checks it, saves the screenshot.
fn test(site: &Path) -> Result<(), String> {
    let clock = Instant::now();
    CHROMIUM.ensure()?;
    // The firmware's words first: its build (when `qemu` has not built it) is the long part.
    let firmware = qemu::lockstep_states();
    let listener = TcpListener::bind(("127.0.0.1", 0)).map_err(|e| e.to_string())?;
    let port = listener.local_addr().map_err(|e| e.to_string())?.port();
    let served = site.to_path_buf();
    std::thread::spawn(move || serve(&listener, &served, WASM_HOLD));
    let url = format!("http://127.0.0.1:{port}/");
    let profile = site.join("chromium-profile");
    let _ = std::fs::remove_dir_all(&profile);
    let mut browser = Browser::start(CHROMIUM.program, &profile, &site.join("chromium.log"))?;
    let checked = drive(&mut browser, &url, site).and_then(|(failures, simd)| {
        let scalar = scalar_scenario(&mut browser, &url)?;
        Ok((failures, simd, scalar))
    });
    let console = std::mem::take(&mut browser.console_errors);
    browser.close();
    let _ = std::fs::remove_dir_all(&profile);
    let (mut failures, simd, scalar) = checked?;
    if !console.is_empty() {
        failures.push(format!(
            "console errors on the page:\n  {}",
            console.join("\n  ")
        ));
    }
    let pages = [("wasm simd128", &simd), ("wasm scalar", &scalar)];
    failures.extend(compare(&pages, &firmware));
    failures.extend(check_sandbox(&pages));
    println!("xtask web --test: {:.0} s", clock.elapsed().as_secs_f64());
    if failures.is_empty() {
        println!("xtask web --test: all checks passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// How long the test's server holds the WebAssembly module back: the page must answer "not
/// ready" meanwhile, as it does while a slow machine compiles the module on a first start.
const WASM_HOLD: Duration = Duration::from_secs(10);

/// The longest the page may take to get ready after the hold. Like every deadline of the
/// test, a bound that turns a hang into a failure, never a claim about speed: each check
/// waits for what it needs (frames drawn, simulated time) and the deadline only ends a wait
/// that would never end.
const READY_DEADLINE: Duration = Duration::from_secs(300);

/// The longest any other wait may take (see [`READY_DEADLINE`]).
const WAIT_DEADLINE: Duration = Duration::from_secs(180);

/// How often a wait probes the page.
const POLL: Duration = Duration::from_millis(100);

/// The probe's expression: the page's state as JSON, `{"ready":false}` before its module is
/// instantiated, `{}` before its script has run.
const PROBE: &str = "window.lagrangeProbe ? window.lagrangeProbe() : '{}'";

/// One probe of the page: its state, or `None` while it is not ready (the script not yet run,
/// the module not yet instantiated, the document being replaced). An exception the page
/// throws is a failure, with the console's messages.
fn probe_once(browser: &mut Browser) -> Result<Option<Json>, String> {
    match browser.evaluate(PROBE) {
        Ok(Evaluated::Value(text)) => {
            let state = Json::parse(&text)?;
            Ok((state.get("ready") == &Json::Bool(true)).then_some(state))
        }
        Ok(Evaluated::Exception(e)) => Err(format!(
            "the page's probe threw: {e}; console: {:?}",
            browser.console_errors
        )),
        // The browser could not evaluate it (a navigation under way): not ready yet.
        Err(_) => Ok(None),
    }
}

/// The page's state, which must be ready.
fn probe(browser: &mut Browser) -> Result<Json, String> {
    probe_once(browser)?.ok_or_else(|| "the page is no longer ready".to_string())
}

/// Probes the page until `done` holds for its state (not ready counts as not done), or fails
/// after `deadline` naming `what`, with the last state and the console's messages.
fn wait_until(
    browser: &mut Browser,
    what: &str,
    deadline: Duration,
    mut done: impl FnMut(&Json) -> bool,
) -> Result<Json, String> {
    let clock = Instant::now();
    let mut last = None;
    loop {
        if let Some(state) = probe_once(browser)? {
            if done(&state) {
                return Ok(state);
            }
            last = Some(state);
        }
        if clock.elapsed() > deadline {
            return Err(format!(
                "{what}: not within {} s; last state {last:?}; console: {:?}",
                deadline.as_secs(),
                browser.console_errors
            ));
        }
        browser.idle(POLL);
    }
}

/// The frames the page has drawn.
fn frames(state: &Json) -> f64 {
    state.get("frames").num().unwrap_or(0.0)
}

/// Each panel's simulated time, s.
fn times(state: &Json) -> Vec<f64> {
    state
        .get("times")
        .items()
        .iter()
        .filter_map(Json::num)
        .collect()
}

/// Waits until the page has drawn `count` frames after `from` and every panel's time has
/// moved; the failure names `after`.
fn frames_advance(
    browser: &mut Browser,
    from: &Json,
    count: f64,
    after: &str,
) -> Result<Json, String> {
    let before = times(from);
    wait_until(
        browser,
        &format!("{count} frames drawn and every scene advanced {after}"),
        WAIT_DEADLINE,
        |s| {
            let now = times(s);
            frames(s) - frames(from) >= count
                && now.len() == before.len()
                && now.iter().zip(&before).all(|(b, a)| b > a)
        },
    )
}

/// Loads the page (its module held back by [`WASM_HOLD`]) and checks it; the failures and the
/// page's scenario lines by precision.
fn drive(
    browser: &mut Browser,
    url: &str,
    site: &Path,
) -> Result<(Vec<String>, BTreeMap<String, String>), String> {
    let mut failures = Vec::new();
    browser.call(
        "Page.navigate",
        &format!(r#"{{"url":{}}}"#, crate::cdp::quote(url)),
    )?;
    let loading = Instant::now();
    let first = wait_until(browser, "the page getting ready", READY_DEADLINE, |_| true)?;
    let waited = loading.elapsed();
    println!(
        "page: ready {:.1} s after loading began (the module held back {} s)",
        waited.as_secs_f64(),
        WASM_HOLD.as_secs()
    );
    if waited < WASM_HOLD {
        failures.push(format!(
            "the page was ready after {:.1} s, before its module was served ({} s): the \
             hold did not hold",
            waited.as_secs_f64(),
            WASM_HOLD.as_secs()
        ));
    }
    let clock = Instant::now();
    let second = frames_advance(browser, &first, 10.0, "after the start")?;
    println!(
        "page: {} frames drawn in {:.1} s; scene times {:?} s",
        frames(&second) - frames(&first),
        clock.elapsed().as_secs_f64(),
        times(&second)
    );
    failures.extend(interact(browser, site)?);
    failures.extend(throws(browser)?);

    // Bad input: the library's errors shown, the instances reset, nothing non-finite drawn,
    // and the page still running.
    let bad = Json::parse(&browser.eval("window.lagrangeBadInput()")?)?;
    let shown: Vec<&str> = bad
        .get("shown")
        .items()
        .iter()
        .filter_map(Json::str)
        .collect();
    println!("page: bad input shown as:\n  {}", shown.join("\n  "));
    if bad.get("dtZero") != &Json::Bool(false) || bad.get("dtNaN") != &Json::Bool(false) {
        failures.push(format!("a dt of 0 or NaN was accepted: {bad:?}"));
    }
    if !shown.iter().any(|s| s.starts_with("0:")) || !shown.iter().any(|s| s.starts_with("1:")) {
        failures.push(format!("the dt errors were not shown: {shown:?}"));
    }
    if bad.get("finite") != &Json::Bool(true) || bad.get("nonFinite").num() != Some(0.0) {
        failures.push(format!("non-finite values after bad input: {bad:?}"));
    }
    let before = probe(browser)?;
    let after = match frames_advance(browser, &before, 5.0, "after bad input") {
        Ok(after) => after,
        Err(e) => {
            failures.push(format!("the page froze after bad input: {e}"));
            before
        }
    };
    if after.get("build").str() != Some("simd128") {
        failures.push(format!(
            "Chromium validates WebAssembly SIMD, but the page loaded the {:?} module",
            after.get("build")
        ));
    }
    Ok((failures, scenario_lines(&after)))
}

/// The scripted scenario's lines of a page's state, by precision.
fn scenario_lines(state: &Json) -> BTreeMap<String, String> {
    let scenario = state.get("scenario");
    let mut lines: BTreeMap<String, String> = SCENARIOS
        .iter()
        .map(|(key, ..)| *key)
        .filter_map(|p| {
            scenario
                .get(p)
                .str()
                .map(|s| (p.to_string(), s.to_string()))
        })
        .collect();
    // The sandbox's scripted pile, as a line of the same map.
    let pile = state.get("sandbox");
    if let (Some(precision), Some(digest)) = (pile.get("precision").str(), pile.get("digest").str())
    {
        let number = |key: &str| pile.get(key).num().unwrap_or(f64::NAN);
        lines.insert(
            SANDBOX.into(),
            format!(
                "{precision} steps={} digest={digest} slowest_ms={} worst={} cap={} failed={}",
                number("steps"),
                number("slowestMs"),
                number("worst"),
                number("cap"),
                pile.get("failed").str().unwrap_or("no"),
            ),
        );
    }
    lines
}

/// The key of the sandbox's scripted pile among the page's lines.
const SANDBOX: &str = "sandbox";

/// Checks the sandbox's scripted pile on each page: its digest the host's (`f64`), no step
/// beyond the contact cap, and prints its slowest step (a figure, not a check).
fn check_sandbox(pages: &[(&str, &BTreeMap<String, String>)]) -> Vec<String> {
    let mut failures = Vec::new();
    let host = match lagrange_web::sandbox::scripted::<f64>(lagrange_web::sandbox::SCRIPT_STEPS) {
        Ok(digest) => format!("{digest:016x}"),
        Err(e) => return vec![format!("sandbox: the host's scripted pile failed: {e}")],
    };
    println!(
        "\nsandbox, the scripted pile (f64, {} steps): digest",
        lagrange_web::sandbox::SCRIPT_STEPS
    );
    let mut shown = vec![format!("host x86_64 {host}")];
    for (name, lines) in pages {
        let Some(line) = lines.get(SANDBOX) else {
            failures.push(format!("sandbox: the {name} page ran no scripted pile"));
            continue;
        };
        let field = |key: &str| {
            line.split_whitespace()
                .find_map(|f| f.strip_prefix(key).and_then(|v| v.strip_prefix('=')))
                .unwrap_or("")
        };
        shown.push(format!("{name} (Chromium) {}", field("digest")));
        let slowest = field("slowest_ms").parse::<f64>().unwrap_or(f64::NAN);
        println!(
            "  {name}: slowest step {slowest:.2} ms in WebAssembly; most contact points in a \
             step {} (cap {})",
            field("worst"),
            field("cap")
        );
        if field("failed") != "no" {
            failures.push(format!(
                "sandbox: the {name} page's scripted pile failed: {line}"
            ));
        }
        if !line.starts_with("f64 ") || field("digest") != host {
            failures.push(format!(
                "sandbox: the {name} page's scripted pile differs from the host's: page {line:?}, host {host}"
            ));
        }
        let (worst, cap) = (field("worst").parse::<f64>(), field("cap").parse::<f64>());
        if !matches!((worst, cap), (Ok(w), Ok(c)) if w > 0.0 && w <= c) {
            failures.push(format!(
                "sandbox: the {name} page's pile did more work than its cap, or none: {line}"
            ));
        }
    }
    println!("  {}", shown.join("  "));
    failures
}

/// The page loaded again with `?scalar`, which makes it take the module without SIMD (what a
/// browser without it runs): its scripted scenario's lines, once it has them.
fn scalar_scenario(browser: &mut Browser, url: &str) -> Result<BTreeMap<String, String>, String> {
    browser.call(
        "Page.navigate",
        &format!(
            r#"{{"url":{}}}"#,
            crate::cdp::quote(&format!("{url}?scalar"))
        ),
    )?;
    let state = wait_until(
        browser,
        "the scalar page's scenario",
        READY_DEADLINE,
        |state| {
            state.get("build").str() == Some("scalar")
                && scenario_lines(state).len() == SCENARIOS.len() + 1
        },
    )?;
    println!("page: loaded again with ?scalar: the scalar module");
    Ok(scenario_lines(&state))
}

/// Saves the page's screenshot to `site/screenshot.png`.
fn screenshot(browser: &mut Browser, site: &Path) -> Result<(), String> {
    let shot = browser.call("Page.captureScreenshot", r#"{"format":"png"}"#)?;
    let png = base64(shot.get("data").str().ok_or("no screenshot data")?)?;
    let path = site.join("screenshot.png");
    std::fs::write(&path, &png).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "page: screenshot {} ({} KiB)",
        path.display(),
        png.len() / 1024
    );
    Ok(())
}

/// The ragdoll's panel on the page.
const RAGDOLL_PANEL: usize = 6;

/// A point of the ragdoll to grab: the top of its head.
const HEAD_TOP: usize = 3;

/// The cart-pole's panel.
const CART_PANEL: usize = 4;

/// Simulated time within which the thrown ragdoll must fall asleep on the page, s.
const RAGDOLL_ASLEEP_BY: f64 = 20.0;

/// Simulated time the cart is pushed for, s, and how far it must have moved, m (from rest
/// under 15 N the cart alone would cover 2 m; the pole takes some).
const PUSH_FOR: f64 = 0.5;
const PUSHED_AT_LEAST: f64 = 0.2;

/// The user's part: the ragdoll, once asleep, grabbed with the mouse and thrown (it wakes);
/// the precision switched to `f32` and an integrator picked (the page goes on). The failures.
///
/// Every check waits for simulated time or drawn frames, not for wall time, so that a loaded
/// machine only makes it slower.
fn interact(browser: &mut Browser, site: &Path) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    let status = |s: &Json| {
        s.get("statuses")
            .items()
            .get(RAGDOLL_PANEL)
            .and_then(Json::num)
    };
    let time = |s: &Json, panel: usize| times(s).get(panel).copied().unwrap_or(f64::NAN);
    let settled = wait_until(
        browser,
        "the thrown ragdoll falling asleep or its time running out",
        WAIT_DEADLINE,
        |s| {
            let t = time(s, RAGDOLL_PANEL);
            status(s) == Some(1.0) || t >= RAGDOLL_ASLEEP_BY || t.is_nan()
        },
    )?;
    // The picture: everything moving but the ragdoll, asleep on the floor (drawn grey).
    screenshot(browser, site)?;
    if status(&settled) == Some(1.0) {
        println!(
            "page: the thrown ragdoll asleep at t = {:.2} s",
            time(&settled, RAGDOLL_PANEL)
        );
        let at = Json::parse(&browser.eval(&format!(
            "window.lagrangeScreenPoint({RAGDOLL_PANEL}, {HEAD_TOP})"
        ))?)?;
        let (Some(x), Some(y)) = (
            at.items().first().and_then(Json::num),
            at.items().get(1).and_then(Json::num),
        ) else {
            return Err(format!("no screen point for the ragdoll's head: {at:?}"));
        };
        let mouse = |browser: &mut Browser, kind: &str, x: f64, y: f64| {
            browser.call(
                "Input.dispatchMouseEvent",
                &format!(
                    r#"{{"type":"{kind}","x":{x},"y":{y},"button":"left","buttons":1,"clickCount":1}}"#
                ),
            )
        };
        mouse(browser, "mousePressed", x, y)?;
        for k in 1..=8 {
            let k = f64::from(k);
            mouse(browser, "mouseMoved", x + 6.0 * k, y - 10.0 * k)?;
            browser.idle(Duration::from_millis(30));
        }
        mouse(browser, "mouseReleased", x + 48.0, y - 80.0)?;
        // The status is the library's, read at once: a wake shows before the next frame.
        match wait_until(browser, "the drag waking the ragdoll", WAIT_DEADLINE, |s| {
            status(s) == Some(0.0)
        }) {
            Ok(_) => println!("page: the asleep ragdoll grabbed by the head and thrown: awake"),
            Err(e) => failures.push(format!("a drag did not wake the asleep ragdoll: {e}")),
        }
    } else {
        failures.push(format!(
            "the thrown ragdoll did not fall asleep on the page within {RAGDOLL_ASLEEP_BY} s \
             of simulated time: {settled:?}"
        ));
    }
    // The cart pushed right with the arrow key for half a second of its simulated time.
    let cart_x = |s: &Json| s.get("cartX").num().unwrap_or(f64::NAN);
    let key = |browser: &mut Browser, kind: &str| {
        browser.call(
            "Input.dispatchKeyEvent",
            &format!(
                r#"{{"type":"{kind}","key":"ArrowRight","code":"ArrowRight","windowsVirtualKeyCode":39}}"#
            ),
        )
    };
    let from = probe(browser)?;
    key(browser, "rawKeyDown")?;
    let pushed = wait_until(browser, "the cart pushed for 0.5 s", WAIT_DEADLINE, |s| {
        time(s, CART_PANEL) - time(&from, CART_PANEL) >= PUSH_FOR
    });
    key(browser, "keyUp")?;
    let to = pushed?;
    let (x0, x1) = (cart_x(&from), cart_x(&to));
    println!("page: the arrow key pushed the cart from x = {x0:.3} m to {x1:.3} m");
    if x1 - x0 < PUSHED_AT_LEAST || x1.is_nan() || x0.is_nan() {
        failures.push(format!(
            "the arrow key did not push the cart: x {x0} -> {x1}"
        ));
    }
    browser.eval("window.lagrangeChoose(-1, 0)")?;
    browser.eval("window.lagrangeChoose(0, 1)")?;
    let before = probe(browser)?;
    let switched = |s: &Json| {
        s.get("double") == &Json::Bool(false)
            && s.get("methods").items().first().and_then(Json::num) == Some(1.0)
    };
    match frames_advance(browser, &before, 5.0, "after switching to f32") {
        Ok(after) if switched(&after) => println!(
            "page: switched to f32 and Stormer-Verlet for the pendulum: done, {} frames after",
            frames(&after) - frames(&before)
        ),
        Ok(after) => failures.push(format!(
            "switching precision or integrator failed: {after:?}"
        )),
        Err(e) => failures.push(format!("the page froze after switching precision: {e}")),
    }
    Ok(failures)
}

/// The panels with contacts (the double pendulum on the floor, the ragdoll) and their rows.
const CONTACT_PANELS: [(usize, u32); 2] = [(5, 4), (RAGDOLL_PANEL, 31)];

/// How long the contact panels are thrown again and again, and how often.
const THROWS_FOR: Duration = Duration::from_secs(10);
const THROW_EVERY: Duration = Duration::from_millis(1250);

/// The contact panels thrown again (reset to their thrown start) every 1.25 s for 10 s: the
/// slowest step each took in WebAssembly, reported (a time, which depends on the machine), and
/// the worst work of any of their steps, checked against the contact solver's documented
/// cap (counts, which do not): rows at most the contact set's, rounds at most the page's cap.
fn throws(browser: &mut Browser) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    let clock = Instant::now();
    let mut thrown = 0;
    while clock.elapsed() < THROWS_FOR {
        for (panel, _) in CONTACT_PANELS {
            browser.eval(&format!("window.lagrangeReset({panel})"))?;
        }
        thrown += 1;
        browser.idle(THROW_EVERY);
    }
    let state = probe(browser)?;
    let cap = state.get("roundsCap").num().unwrap_or(0.0);
    for (panel, rows_cap) in CONTACT_PANELS {
        let slowest = state
            .get("slowest")
            .items()
            .get(panel)
            .and_then(Json::num)
            .unwrap_or(f64::NAN);
        let work = state.get("work").items().get(panel).map(Json::items);
        let count = |k: usize| work.and_then(|w| w.get(k)).and_then(Json::num);
        let (rows, rounds) = (count(0), count(1));
        println!(
            "page: panel {panel} thrown {thrown} times in {} s: slowest step {slowest:.3} ms in \
             WebAssembly; worst work {rows:?} rows, {rounds:?} rounds (caps {rows_cap}, {cap})",
            THROWS_FOR.as_secs()
        );
        match (rows, rounds) {
            (Some(r), Some(k)) if r <= f64::from(rows_cap) && k <= cap && r > 0.0 => {}
            _ => failures.push(format!(
                "panel {panel}: a contact step did more work than its cap, or none: rows \
                 {rows:?} (cap {rows_cap}), rounds {rounds:?} (cap {cap})"
            )),
        }
    }
    Ok(failures)
}

/// Compares the page's scenario with the host's and the firmware's; the failures.
fn compare(
    pages: &[(&str, &BTreeMap<String, String>)],
    firmware: &Result<BTreeMap<usize, Option<Vec<u64>>>, String>,
) -> Vec<String> {
    let mut failures = Vec::new();
    if let Err(e) = firmware {
        failures.push(format!("no firmware words from QEMU: {e}"));
    }
    println!("\nscripted scenarios ({STEPS} frames): words and digest");
    for (key, case, precision, run) in SCENARIOS {
        let host = match run(STEPS) {
            Ok(outcome) => outcome.words().to_vec(),
            Err(e) => {
                failures.push(format!("{key}: the host's scenario failed: {e}"));
                continue;
            }
        };
        let id = CASES
            .iter()
            .position(|c| c.system == case && c.precision == precision);
        let m4f = firmware
            .as_ref()
            .ok()
            .and_then(|states| states.get(&id?).cloned().flatten());
        let show = |words: Option<&Vec<u64>>| {
            words.map_or_else(|| "missing".to_string(), |w| format!("{:016x}", digest(w)))
        };
        let mut shown = vec![format!("host x86_64 {}", show(Some(&host)))];
        for (name, page) in pages {
            let wasm = page.get(key).map(|line| parse_scenario(line));
            let wasm_words = match &wasm {
                Some(Ok((words, digest_shown))) => {
                    if *digest_shown != digest(words) {
                        failures.push(format!(
                            "{key}: the {name} page's digest does not match its words"
                        ));
                    }
                    Some(words)
                }
                Some(Err(e)) => {
                    failures.push(e.clone());
                    None
                }
                None => None,
            };
            shown.push(format!("{name} (Chromium) {}", show(wasm_words)));
            if wasm_words != Some(&host) {
                failures.push(format!(
                    "{key}: the {name} page's scenario differs from the host's: page \
                     {wasm:?}, host {host:x?}"
                ));
            }
        }
        shown.push(format!("M4F (QEMU) {}", show(m4f.as_ref())));
        println!("  {key} ({case}): {}", shown.join("  "));
        if m4f.as_ref() != Some(&host) {
            failures.push(format!(
                "{key}: the firmware's scenario differs from the host's: M4F {m4f:x?}, \
                 host {host:x?}"
            ));
        }
    }
    if failures.is_empty() {
        println!(
            "  identical bits: host x86_64 (banks in lanes) = wasm in Chromium, with SIMD (in \
             lanes) and without (one by one) = Cortex-M4F under QEMU (one by one)"
        );
    }
    failures
}
