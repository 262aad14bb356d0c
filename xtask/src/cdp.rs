//! Headless Chromium driven over the DevTools protocol, with no dependency: the browser
//! started with `--remote-debugging-pipe` reads commands on its file descriptor 3 and writes
//! replies and events on 4, each a JSON text ended by a NUL byte. A shell hands our pipes to
//! those descriptors (`exec chromium ... 3<&0 4>&1`). A small JSON reader decodes the replies.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// What an expression evaluated in the page gave ([`Browser::evaluate`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Evaluated {
    /// Its value, a string.
    Value(String),
    /// The exception it threw, described.
    Exception(String),
}

/// A JSON value.
#[derive(Debug, Clone, PartialEq)]
pub enum Json {
    /// `null`.
    Null,
    /// `true` or `false`.
    Bool(bool),
    /// A number.
    Num(f64),
    /// A string.
    Str(String),
    /// An array.
    Arr(Vec<Json>),
    /// An object, its members in order.
    Obj(Vec<(String, Json)>),
}

/// `Json::Null`, for lookups that find nothing.
static NULL: Json = Json::Null;

impl Json {
    /// Parses `text`.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut reader = Reader {
            bytes: text.as_bytes(),
            at: 0,
        };
        let value = reader.value()?;
        reader.space();
        if reader.at == reader.bytes.len() {
            Ok(value)
        } else {
            Err(format!("trailing characters in JSON at {}", reader.at))
        }
    }

    /// Member `key` of an object (`Null` when missing).
    pub fn get(&self, key: &str) -> &Self {
        match self {
            Self::Obj(members) => members
                .iter()
                .find(|(k, _)| k == key)
                .map_or(&NULL, |(_, v)| v),
            _ => &NULL,
        }
    }

    /// The string, if it is one.
    pub fn str(&self) -> Option<&str> {
        match self {
            Self::Str(s) => Some(s),
            _ => None,
        }
    }

    /// The number, if it is one.
    pub fn num(&self) -> Option<f64> {
        match self {
            Self::Num(x) => Some(*x),
            _ => None,
        }
    }

    /// The elements, if it is an array (else none).
    pub fn items(&self) -> &[Self] {
        match self {
            Self::Arr(items) => items,
            _ => &[],
        }
    }
}

/// A JSON string literal of `s`.
pub fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The cursor of [`Json::parse`].
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn space(&mut self) {
        while self.bytes.get(self.at).is_some_and(u8::is_ascii_whitespace) {
            self.at += 1;
        }
    }

    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.at).copied()
    }

    fn expect(&mut self, word: &str) -> Result<(), String> {
        if self.bytes[self.at..].starts_with(word.as_bytes()) {
            self.at += word.len();
            Ok(())
        } else {
            Err(format!("expected {word} in JSON at {}", self.at))
        }
    }

    fn value(&mut self) -> Result<Json, String> {
        self.space();
        match self.peek() {
            Some(b'n') => self.expect("null").map(|()| Json::Null),
            Some(b't') => self.expect("true").map(|()| Json::Bool(true)),
            Some(b'f') => self.expect("false").map(|()| Json::Bool(false)),
            Some(b'"') => self.string().map(Json::Str),
            Some(b'[') => {
                self.at += 1;
                let mut items = Vec::new();
                self.space();
                if self.peek() == Some(b']') {
                    self.at += 1;
                    return Ok(Json::Arr(items));
                }
                loop {
                    items.push(self.value()?);
                    self.space();
                    match self.peek() {
                        Some(b',') => self.at += 1,
                        Some(b']') => {
                            self.at += 1;
                            return Ok(Json::Arr(items));
                        }
                        _ => return Err(format!("bad array in JSON at {}", self.at)),
                    }
                }
            }
            Some(b'{') => {
                self.at += 1;
                let mut members = Vec::new();
                self.space();
                if self.peek() == Some(b'}') {
                    self.at += 1;
                    return Ok(Json::Obj(members));
                }
                loop {
                    self.space();
                    let key = self.string()?;
                    self.space();
                    self.expect(":")?;
                    members.push((key, self.value()?));
                    self.space();
                    match self.peek() {
                        Some(b',') => self.at += 1,
                        Some(b'}') => {
                            self.at += 1;
                            return Ok(Json::Obj(members));
                        }
                        _ => return Err(format!("bad object in JSON at {}", self.at)),
                    }
                }
            }
            _ => {
                let start = self.at;
                while self
                    .peek()
                    .is_some_and(|b| b.is_ascii_digit() || b"+-.eE".contains(&b))
                {
                    self.at += 1;
                }
                std::str::from_utf8(&self.bytes[start..self.at])
                    .ok()
                    .and_then(|s| s.parse().ok())
                    .map(Json::Num)
                    .ok_or_else(|| format!("bad value in JSON at {start}"))
            }
        }
    }

    fn hex4(&mut self) -> Result<u32, String> {
        let digits = self
            .bytes
            .get(self.at..self.at + 4)
            .and_then(|d| std::str::from_utf8(d).ok())
            .and_then(|d| u32::from_str_radix(d, 16).ok())
            .ok_or_else(|| format!("bad \\u escape in JSON at {}", self.at))?;
        self.at += 4;
        Ok(digits)
    }

    fn string(&mut self) -> Result<String, String> {
        self.expect("\"")?;
        let mut out = Vec::new();
        loop {
            let b = self.peek().ok_or("unterminated string in JSON")?;
            self.at += 1;
            match b {
                b'"' => return String::from_utf8(out).map_err(|e| e.to_string()),
                b'\\' => {
                    let e = self.peek().ok_or("unterminated escape in JSON")?;
                    self.at += 1;
                    let c = match e {
                        b'n' => '\n',
                        b't' => '\t',
                        b'r' => '\r',
                        b'b' => '\u{8}',
                        b'f' => '\u{c}',
                        b'u' => {
                            let mut code = self.hex4()?;
                            if (0xd800..0xdc00).contains(&code)
                                && self.bytes[self.at..].starts_with(b"\\u")
                            {
                                self.at += 2;
                                let low = self.hex4()?;
                                code =
                                    0x10000 + ((code - 0xd800) << 10) + (low.wrapping_sub(0xdc00));
                            }
                            char::from_u32(code).unwrap_or('\u{fffd}')
                        }
                        other => char::from(other),
                    };
                    let mut buf = [0; 4];
                    out.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
                }
                b => out.push(b),
            }
        }
    }
}

/// Decodes standard base64 (the screenshot).
pub fn base64(text: &str) -> Result<Vec<u8>, String> {
    let value = |c: u8| -> Option<u32> {
        match c {
            b'A'..=b'Z' => Some(u32::from(c - b'A')),
            b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
            b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
            b'+' => Some(62),
            b'/' => Some(63),
            _ => None,
        }
    };
    let digits: Vec<u8> = text.bytes().filter(|&c| c != b'=' && c != b'\n').collect();
    let mut out = Vec::with_capacity(digits.len() * 3 / 4);
    for chunk in digits.chunks(4) {
        let mut acc = 0u32;
        for &c in chunk {
            acc = (acc << 6) | value(c).ok_or("bad base64")?;
        }
        let bits = 6 * chunk.len();
        acc <<= 24 - bits;
        let bytes = acc.to_be_bytes();
        out.extend_from_slice(&bytes[1..1 + bits / 8]);
    }
    Ok(out)
}

/// A running browser and the session of its one page.
pub struct Browser {
    child: Child,
    commands: ChildStdin,
    replies: Receiver<String>,
    next_id: u64,
    session: Option<String>,
    /// Console errors and uncaught exceptions the page reported.
    pub console_errors: Vec<String>,
}

/// How long one command may take: a bound that turns a hung browser into a failure, not a
/// claim about speed (a loaded machine starting Chromium for the first time is slow).
const REPLY_TIMEOUT: Duration = Duration::from_secs(180);

impl Browser {
    /// Starts `chromium` headless with its stderr to `log`, and opens a page attached to a
    /// session with the runtime, log and page domains enabled.
    pub fn start(chromium: &str, profile: &Path, log: &Path) -> Result<Self, String> {
        let log = std::fs::File::create(log).map_err(|e| format!("{}: {e}", log.display()))?;
        let mut child = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" 3<&0 4>&1 </dev/null >/dev/null")
            .arg(chromium)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-dev-shm-usage",
                "--no-first-run",
                "--no-default-browser-check",
                "--disable-extensions",
                "--disable-background-networking",
                "--mute-audio",
                "--remote-debugging-pipe",
                "--window-size=1400,1100",
            ])
            .arg(format!("--user-data-dir={}", profile.display()))
            .arg("about:blank")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(log)
            .spawn()
            .map_err(|e| format!("could not start {chromium}: {e}"))?;
        let commands = child.stdin.take().ok_or("no pipe to the browser")?;
        let stdout = child.stdout.take().ok_or("no pipe from the browser")?;
        let (send, replies) = mpsc::channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(stdout);
            loop {
                let mut message = Vec::new();
                match reader.read_until(0, &mut message) {
                    Ok(0) | Err(_) => break,
                    Ok(_) => {
                        if message.last() == Some(&0) {
                            message.pop();
                        }
                        if send
                            .send(String::from_utf8_lossy(&message).into_owned())
                            .is_err()
                        {
                            break;
                        }
                    }
                }
            }
        });
        let mut browser = Self {
            child,
            commands,
            replies,
            next_id: 0,
            session: None,
            console_errors: Vec::new(),
        };
        let target = browser.call("Target.createTarget", r#"{"url":"about:blank"}"#)?;
        let id = target
            .get("targetId")
            .str()
            .ok_or("Target.createTarget gave no targetId")?
            .to_string();
        let attached = browser.call(
            "Target.attachToTarget",
            &format!(r#"{{"targetId":{},"flatten":true}}"#, quote(&id)),
        )?;
        browser.session = Some(
            attached
                .get("sessionId")
                .str()
                .ok_or("Target.attachToTarget gave no sessionId")?
                .to_string(),
        );
        for domain in ["Runtime.enable", "Log.enable", "Page.enable"] {
            browser.call(domain, "{}")?;
        }
        browser.call(
            "Emulation.setDeviceMetricsOverride",
            r#"{"width":1400,"height":1100,"deviceScaleFactor":1,"mobile":false}"#,
        )?;
        Ok(browser)
    }

    /// Sends `method` with `params` (a JSON object) to the page's session (the browser's
    /// before there is one) and waits for its result; events that arrive meanwhile are
    /// looked through for console errors.
    pub fn call(&mut self, method: &str, params: &str) -> Result<Json, String> {
        self.next_id += 1;
        let id = self.next_id;
        let session = self
            .session
            .as_ref()
            .map(|s| format!(r#","sessionId":{}"#, quote(s)))
            .unwrap_or_default();
        let message = format!(
            r#"{{"id":{id},"method":{},"params":{params}{session}}}"#,
            quote(method)
        );
        self.commands
            .write_all(message.as_bytes())
            .and_then(|()| self.commands.write_all(&[0]))
            .and_then(|()| self.commands.flush())
            .map_err(|e| format!("{method}: the browser's pipe is closed ({e})"))?;
        let deadline = Instant::now() + REPLY_TIMEOUT;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let text = match self.replies.recv_timeout(left) {
                Ok(text) => text,
                Err(RecvTimeoutError::Timeout) => return Err(format!("{method}: no reply")),
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(format!("{method}: the browser exited"))
                }
            };
            let reply = Json::parse(&text)?;
            if reply.get("id").num() == Some(id as f64) {
                if let Json::Obj(_) = reply.get("error") {
                    return Err(format!(
                        "{method}: {}",
                        reply.get("error").get("message").str().unwrap_or("error")
                    ));
                }
                return Ok(reply.get("result").clone());
            }
            self.event(&reply);
        }
    }

    /// Notes a console error or an uncaught exception.
    fn event(&mut self, event: &Json) {
        let params = event.get("params");
        match event.get("method").str() {
            Some("Runtime.exceptionThrown") => {
                let details = params.get("exceptionDetails");
                let text = details
                    .get("exception")
                    .get("description")
                    .str()
                    .or_else(|| details.get("text").str())
                    .unwrap_or("exception");
                self.console_errors.push(format!("uncaught: {text}"));
            }
            Some("Runtime.consoleAPICalled")
                if matches!(params.get("type").str(), Some("error" | "assert")) =>
            {
                let args: Vec<String> = params
                    .get("args")
                    .items()
                    .iter()
                    .map(|a| {
                        a.get("value")
                            .str()
                            .or_else(|| a.get("description").str())
                            .unwrap_or("?")
                            .to_string()
                    })
                    .collect();
                self.console_errors
                    .push(format!("console.error: {}", args.join(" ")));
            }
            Some("Log.entryAdded") if params.get("entry").get("level").str() == Some("error") => {
                let entry = params.get("entry");
                self.console_errors.push(format!(
                    "log: {} {}",
                    entry.get("text").str().unwrap_or("?"),
                    entry.get("url").str().unwrap_or("")
                ));
            }
            _ => {}
        }
    }

    /// Evaluates `expression` in the page: its value (which must be a string) or the
    /// exception it threw; `Err` when the browser could not evaluate it at all (a page that
    /// is being replaced, a closed pipe).
    pub fn evaluate(&mut self, expression: &str) -> Result<Evaluated, String> {
        let result = self.call(
            "Runtime.evaluate",
            &format!(
                r#"{{"expression":{},"returnByValue":true}}"#,
                quote(expression)
            ),
        )?;
        if let Json::Obj(_) = result.get("exceptionDetails") {
            let details = result.get("exceptionDetails");
            let text = details
                .get("exception")
                .get("description")
                .str()
                .or_else(|| details.get("text").str())
                .unwrap_or("exception");
            return Ok(Evaluated::Exception(text.to_string()));
        }
        result
            .get("result")
            .get("value")
            .str()
            .map(|v| Evaluated::Value(v.to_string()))
            .ok_or_else(|| format!("{expression}: not a string"))
    }

    /// Evaluates `expression` in the page: its value, which must be a string; an exception
    /// it threw is an `Err` naming it.
    pub fn eval(&mut self, expression: &str) -> Result<String, String> {
        match self.evaluate(expression)? {
            Evaluated::Value(v) => Ok(v),
            Evaluated::Exception(e) => Err(format!("{expression}: {e}")),
        }
    }

    /// Reads events for `time` (so that console errors arriving meanwhile are noted).
    pub fn idle(&mut self, time: Duration) {
        let deadline = Instant::now() + time;
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match self.replies.recv_timeout(left) {
                Ok(text) => {
                    if let Ok(event) = Json::parse(&text) {
                        self.event(&event);
                    }
                }
                Err(_) => break,
            }
        }
    }

    /// Closes the browser (killing it if it does not exit within a few seconds).
    pub fn close(mut self) {
        self.session = None;
        let _ = self.call("Browser.close", "{}");
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[cfg(test)]
mod tests {
    use super::{base64, quote, Json};

    #[test]
    fn json_reads_what_chromium_writes() -> Result<(), String> {
        let text = r#"{"id":7,"result":{"result":{"type":"string","value":"a\"b\\c\u00e9\ud83d\ude00\n"}},
            "list":[1,-2.5e3,true,false,null,{}],"sessionId":"S"}"#;
        let v = Json::parse(text)?;
        assert_eq!(v.get("id").num(), Some(7.0));
        assert_eq!(
            v.get("result").get("result").get("value").str(),
            Some("a\"b\\c\u{e9}\u{1f600}\n")
        );
        let list = v.get("list").items();
        assert_eq!(list.len(), 6);
        assert_eq!(list[1].num(), Some(-2500.0));
        assert_eq!(list[2], Json::Bool(true));
        assert_eq!(v.get("missing"), &Json::Null);
        assert!(Json::parse("{\"a\":1} x").is_err());
        assert!(Json::parse("[1,").is_err());
        let quoted = quote("say \"hi\"\n\\");
        assert_eq!(Json::parse(&quoted)?.str(), Some("say \"hi\"\n\\"));
        Ok(())
    }

    #[test]
    fn base64_decodes() -> Result<(), String> {
        assert_eq!(base64("")?, b"");
        assert_eq!(base64("Zg==")?, b"f");
        assert_eq!(base64("Zm8=")?, b"fo");
        assert_eq!(base64("Zm9v")?, b"foo");
        assert_eq!(base64("iVBORw0KGgo=")?, b"\x89PNG\r\n\x1a\n");
        assert!(base64("Zm9v!").is_err());
        Ok(())
    }
}
