//! `cargo xtask web`: the interactive page, the library compiled to WebAssembly.
//!
//! 1. Installs the `wasm32-unknown-unknown` target with rustup when it is missing.
//! 2. Builds `web/` (crate `lagrange-web`, plain C ABI exports) for it in the `web` profile.
//! 3. Writes the static site to `target/lagrange-web/`: `web/site/*` and the `.wasm`; no CDN,
//!    no network at run time.
//! 4. Serves it on 127.0.0.1 and prints the URL (`--no-serve`: stops after the build).
//!
//! `--test` drives the page in headless Chromium (Debian's `chromium`, installed by apt-get
//! when missing) over the DevTools protocol ([`crate::cdp`]) and checks that it loads without
//! console errors, that frames advance, that the scripted scenario's words and digest equal
//! the host's (x86_64, computed here) and the firmware's (under QEMU, `crate::qemu`), and that
//! bad input (a dt of 0 or NaN, an absurd throw) shows the library's error, resets the
//! instance and leaves every drawn value finite. It saves `target/lagrange-web/screenshot.png`.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use lagrange_cases::{scripted, CASES, STEPS};

use crate::cdp::{base64, Browser, Json};
use crate::cmd;
use crate::cross;
use crate::qemu;

/// The WebAssembly target.
const WASM: &str = "wasm32-unknown-unknown";

/// The browser, from Debian's package of the same name.
const CHROMIUM: &str = "chromium";

/// The port `cargo xtask web` serves on when it is free (else any free one).
const PORT: u16 = 8018;

/// The lockstep case the page's scenario is, by precision.
const SCENE_CASE: &str = "scene (sleep, wake)";

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
        serve(&listener, &site);
        Ok(())
    }
}

/// Builds the wasm and writes the site; its directory.
fn build() -> Result<PathBuf, String> {
    let clock = Instant::now();
    cross::ensure_rustup_target(WASM)?;
    let root = cmd::project_root();
    let target = root.join("target");
    cmd::run(
        cmd::cargo()
            .args([
                "build",
                "--quiet",
                "-p",
                "lagrange-web",
                "--lib",
                "--target",
                WASM,
            ])
            .args(["--profile", "web", "--target-dir"])
            .arg(&target),
    )?;
    let site = target.join("lagrange-web");
    std::fs::create_dir_all(&site).map_err(|e| format!("{}: {e}", site.display()))?;
    let copy = |from: &Path, to: &Path| {
        std::fs::copy(from, to)
            .map(|_| ())
            .map_err(|e| format!("copying {} to {}: {e}", from.display(), to.display()))
    };
    let wasm = target.join(WASM).join("web").join("lagrange_web.wasm");
    copy(&wasm, &site.join("lagrange_web.wasm"))?;
    let sources = root.join("web").join("site");
    let entries = std::fs::read_dir(&sources).map_err(|e| format!("{}: {e}", sources.display()))?;
    for entry in entries.flatten() {
        copy(&entry.path(), &site.join(entry.file_name()))?;
    }
    let size = std::fs::metadata(site.join("lagrange_web.wasm")).map_or(0, |m| m.len());
    println!(
        "xtask web: built in {:.0} s: {} ({} KiB of wasm)",
        clock.elapsed().as_secs_f64(),
        site.display(),
        size / 1024
    );
    Ok(site)
}

/// Serves `site` on `listener` until the process ends, one thread per connection.
fn serve(listener: &TcpListener, site: &Path) {
    for stream in listener.incoming().flatten() {
        let site = site.to_path_buf();
        std::thread::spawn(move || {
            let _ = respond(stream, &site);
        });
    }
}

/// Answers one GET: a file of the site by name, else 404.
fn respond(mut stream: TcpStream, site: &Path) -> std::io::Result<()> {
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

/// Installs Debian's `chromium` with apt-get when it does not run.
fn ensure_chromium() -> Result<(), String> {
    if qemu::works(Path::new(CHROMIUM), &["--version"]) {
        return Ok(());
    }
    println!("{CHROMIUM} is missing: installing Debian's package");
    let clock = Instant::now();
    cmd::run(Command::new("apt-get").args(["update", "-qq"]))?;
    cmd::run(
        Command::new("apt-get")
            .env("DEBIAN_FRONTEND", "noninteractive")
            .args(["install", "-y", "-qq", "--no-install-recommends", CHROMIUM]),
    )?;
    if qemu::works(Path::new(CHROMIUM), &["--version"]) {
        println!(
            "{CHROMIUM} installed in {:.0} s",
            clock.elapsed().as_secs_f64()
        );
        Ok(())
    } else {
        Err(format!(
            "{CHROMIUM} still does not run after apt-get install"
        ))
    }
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
    ensure_chromium()?;
    // The firmware's words first: its build (when `qemu` has not built it) is the long part.
    let firmware = qemu::lockstep_states();
    let listener = TcpListener::bind(("127.0.0.1", 0)).map_err(|e| e.to_string())?;
    let port = listener.local_addr().map_err(|e| e.to_string())?.port();
    let served = site.to_path_buf();
    std::thread::spawn(move || serve(&listener, &served));
    let url = format!("http://127.0.0.1:{port}/");
    let profile = site.join("chromium-profile");
    let _ = std::fs::remove_dir_all(&profile);
    let mut browser = Browser::start(CHROMIUM, &profile, &site.join("chromium.log"))?;
    let checked = drive(&mut browser, &url, site);
    let console = std::mem::take(&mut browser.console_errors);
    browser.close();
    let _ = std::fs::remove_dir_all(&profile);
    let (mut failures, page) = checked?;
    if !console.is_empty() {
        failures.push(format!(
            "console errors on the page:\n  {}",
            console.join("\n  ")
        ));
    }
    failures.extend(compare(&page, &firmware));
    println!("xtask web --test: {:.0} s", clock.elapsed().as_secs_f64());
    if failures.is_empty() {
        println!("xtask web --test: all checks passed");
        Ok(())
    } else {
        Err(failures.join("\n"))
    }
}

/// Polls `window.lagrangeProbe()` until the page is ready.
fn probe(browser: &mut Browser) -> Result<Json, String> {
    let text = browser.eval("window.lagrangeProbe ? window.lagrangeProbe() : '{}'")?;
    Json::parse(&text)
}

/// Loads the page and checks it; the failures and the page's scenario lines by precision.
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
    let deadline = Instant::now() + Duration::from_secs(60);
    let first = loop {
        let state = probe(browser)?;
        if state.get("ready") == &Json::Bool(true) {
            break state;
        }
        if Instant::now() > deadline {
            return Err(format!(
                "the page at {url} did not get ready in 60 s; console: {:?}",
                browser.console_errors
            ));
        }
        browser.idle(Duration::from_millis(200));
    };
    browser.idle(Duration::from_secs(2));
    let second = probe(browser)?;
    let frames = |s: &Json| s.get("frames").num().unwrap_or(0.0);
    let times = |s: &Json| -> Vec<f64> {
        s.get("times")
            .items()
            .iter()
            .filter_map(Json::num)
            .collect()
    };
    let drawn = frames(&second) - frames(&first);
    println!(
        "page: {drawn} frames drawn in 2 s; scene times {:?} s",
        times(&second)
    );
    if drawn < 10.0 {
        failures.push(format!("frames do not advance: {drawn} in 2 s"));
    }
    let stuck = times(&first)
        .iter()
        .zip(times(&second))
        .filter(|(a, b)| *b <= **a)
        .count();
    if stuck > 0 || times(&second).is_empty() {
        failures.push(format!("{stuck} scenes did not advance in 2 s"));
    }
    failures.extend(interact(browser, site)?);

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
    browser.idle(Duration::from_secs(1));
    let after = probe(browser)?;
    if frames(&after) - frames(&before) < 5.0 {
        failures.push("the page froze after bad input".into());
    }
    let scenario = after.get("scenario");
    let lines = ["f32", "f64"]
        .into_iter()
        .filter_map(|p| {
            scenario
                .get(p)
                .str()
                .map(|s| (p.to_string(), s.to_string()))
        })
        .collect();
    Ok((failures, lines))
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

/// The user's part: the ragdoll, once asleep, grabbed with the mouse and thrown (it wakes);
/// the precision switched to `f32` and an integrator picked (the page goes on). The failures.
fn interact(browser: &mut Browser, site: &Path) -> Result<Vec<String>, String> {
    let mut failures = Vec::new();
    let status = |browser: &mut Browser| -> Result<Option<f64>, String> {
        Ok(probe(browser)?
            .get("statuses")
            .items()
            .get(RAGDOLL_PANEL)
            .and_then(Json::num))
    };
    let deadline = Instant::now() + Duration::from_secs(20);
    while status(browser)? != Some(1.0) && Instant::now() < deadline {
        browser.idle(Duration::from_millis(250));
    }
    // The picture: everything moving but the ragdoll, asleep on the floor (drawn grey).
    screenshot(browser, site)?;
    if status(browser)? == Some(1.0) {
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
        browser.idle(Duration::from_millis(100));
        let woken = status(browser)?;
        println!(
            "page: the asleep ragdoll grabbed by the head and thrown: status {woken:?} (0 awake)"
        );
        if woken != Some(0.0) {
            failures.push(format!(
                "a drag did not wake the asleep ragdoll (status {woken:?})"
            ));
        }
    } else {
        failures.push("the thrown ragdoll did not fall asleep on the page within 20 s".into());
    }
    // The cart pushed right with the arrow key for half a second.
    let cart = |browser: &mut Browser| -> Result<f64, String> {
        Ok(probe(browser)?.get("cartX").num().unwrap_or(f64::NAN))
    };
    let key = |browser: &mut Browser, kind: &str| {
        browser.call(
            "Input.dispatchKeyEvent",
            &format!(
                r#"{{"type":"{kind}","key":"ArrowRight","code":"ArrowRight","windowsVirtualKeyCode":39}}"#
            ),
        )
    };
    let from = cart(browser)?;
    key(browser, "rawKeyDown")?;
    browser.idle(Duration::from_millis(500));
    key(browser, "keyUp")?;
    let to = cart(browser)?;
    println!("page: the arrow key pushed the cart from x = {from:.3} m to {to:.3} m");
    if to.is_nan() || from.is_nan() || to - from < 0.2 {
        failures.push(format!(
            "the arrow key did not push the cart: x {from} -> {to}"
        ));
    }
    browser.eval("window.lagrangeChoose(-1, 0)")?;
    browser.eval("window.lagrangeChoose(0, 1)")?;
    let before = probe(browser)?;
    browser.idle(Duration::from_secs(1));
    let after = probe(browser)?;
    let frames = |s: &Json| s.get("frames").num().unwrap_or(0.0);
    let switched = after.get("double") == &Json::Bool(false)
        && after.get("methods").items().first().and_then(Json::num) == Some(1.0);
    println!(
        "page: switched to f32 and Stormer-Verlet for the pendulum: {}, {} frames in 1 s after",
        if switched { "done" } else { "NOT done" },
        frames(&after) - frames(&before)
    );
    if !switched || frames(&after) - frames(&before) < 5.0 {
        failures.push(format!(
            "switching precision or integrator failed: {after:?}"
        ));
    }
    Ok(failures)
}

/// Compares the page's scenario with the host's and the firmware's; the failures.
fn compare(
    page: &BTreeMap<String, String>,
    firmware: &Result<BTreeMap<usize, Option<Vec<u64>>>, String>,
) -> Vec<String> {
    let mut failures = Vec::new();
    if let Err(e) = firmware {
        failures.push(format!("no firmware words from QEMU: {e}"));
    }
    println!("\nscripted scenario ({SCENE_CASE}, {STEPS} frames): words and digest");
    for precision in ["f32", "f64"] {
        let host = if precision == "f32" {
            scripted::<f32>(STEPS)
        } else {
            scripted::<f64>(STEPS)
        };
        let host = match host {
            Ok(outcome) => outcome.words().to_vec(),
            Err(e) => {
                failures.push(format!("{precision}: the host's scenario failed: {e}"));
                continue;
            }
        };
        let id = CASES
            .iter()
            .position(|c| c.system == SCENE_CASE && c.precision == precision);
        let m4f = firmware
            .as_ref()
            .ok()
            .and_then(|states| states.get(&id?).cloned().flatten());
        let wasm = page.get(precision).map(|line| parse_scenario(line));
        let show = |words: Option<&Vec<u64>>| {
            words.map_or_else(|| "missing".to_string(), |w| format!("{:016x}", digest(w)))
        };
        let wasm_words = match &wasm {
            Some(Ok((words, shown))) => {
                if *shown != digest(words) {
                    failures.push(format!(
                        "{precision}: the page's digest does not match its words"
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
        println!(
            "  {precision}: host x86_64 {}  wasm (Chromium) {}  M4F (QEMU) {}",
            show(Some(&host)),
            show(wasm_words),
            show(m4f.as_ref())
        );
        if wasm_words != Some(&host) {
            failures.push(format!(
                "{precision}: the page's scenario differs from the host's: page {wasm:?}, host {host:x?}"
            ));
        }
        if m4f.as_ref() != Some(&host) {
            failures.push(format!(
                "{precision}: the firmware's scenario differs from the host's: M4F {m4f:x?}, \
                 host {host:x?}"
            ));
        }
    }
    if failures.is_empty() {
        println!("  identical bits: host x86_64 = wasm in Chromium = Cortex-M4F under QEMU");
    }
    failures
}
