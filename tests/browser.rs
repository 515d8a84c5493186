//! Issue 25 item 4: the view of `models/windmill.mbd` in a real browser. Headless Chromium
//! (Debian's package, installed here when it is missing and the tests run as root) loads the
//! page: it must report itself ready with no error, and screenshots at two times must show the
//! scene (not a blank page) and the blades in other places.

use crate::cli::{code, mbd, stderr, temp};
use resvg::tiny_skia::Pixmap;
use std::path::{Path, PathBuf};
use std::process::Command;

const CHROMIUM: &str = "/usr/bin/chromium";

/// Chromium, installed from Debian's packages if it is missing. One test installs it while the
/// others wait: two `apt-get`s at once fail on dpkg's lock (seen on a clean machine).
fn chromium() -> PathBuf {
    static INSTALL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = INSTALL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let path = PathBuf::from(CHROMIUM);
    if !path.exists() {
        let apt = |args: &[&str]| {
            Command::new("apt-get")
                .args(args)
                .env("DEBIAN_FRONTEND", "noninteractive")
                .output()
                .map(|o| o.status.success())
                .unwrap_or(false)
        };
        if !apt(&["install", "-y", "-q", "chromium"]) {
            apt(&["update", "-q"]);
            assert!(
                apt(&["install", "-y", "-q", "chromium"]),
                "this test needs Debian's chromium: apt-get install chromium (as root)"
            );
        }
    }
    assert!(path.exists(), "no {CHROMIUM} after installing chromium");
    path
}

/// Chromium headless on `url` with these extra flags; its stdout.
fn headless(url: &str, extra: &[&str], profile: &Path) -> String {
    let out = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--window-size=1000,750",
            "--virtual-time-budget=4000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .output()
        .expect("start chromium");
    assert!(
        out.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).to_string()
}

/// The page at `url` reports itself ready and no error (caught into the DOM by the viewer).
fn ready_without_errors(url: &str, profile: &Path) {
    let dom = headless(url, &["--dump-dom"], profile);
    assert!(
        dom.contains("data-mbd-ready=\"1\""),
        "the page did not finish: {}",
        &dom[..dom.len().min(2000)]
    );
    let errors = dom.split("data-mbd-errors=\"").nth(1);
    assert!(
        errors.is_none(),
        "errors on the page: {}",
        errors.unwrap_or("").chars().take(500).collect::<String>()
    );
}

/// Springs (helices), a torque (a double-headed arrow), a follower force and the drawn-only
/// shapes of docs/language.md build without errors in the browser.
#[test]
fn springs_torques_and_shapes_render_in_chromium() {
    let model = temp(
        "browser_springs.mbd",
        "model springs \"springs, loads and shapes\"
gravity = (0, -9.81, 0) m/s^2
ground earth
rigid box {
    mass = 1 kg, inertia = (0.01, 0.02, 0.03) kg*m^2, at = (0, -1, 0) m
    marker nose { at = (0.1, 0, 0) m, axes = rotate(z, 90 deg) }
}
spring hang(earth, box) { stiffness = 100 N/m, damping = 1 N*s/m, length = 0.9 m }
torsional_spring twist(earth @ (0, -1, 0) m, box) { stiffness = 10 N*m/rad }
torque spin on box = (0, 0, 1) N*m * ramp(0 s, 0.5 s)
force thrust follower on box.nose = (2, 0, 0) N
cylinder post(earth @ (0, -2, 0) m, earth @ (0, 0.2, 0) m) { radius = 2 cm }
box cab on box.nose { size = (0.1, 0.1, 0.1) m, color = (0.8, 0.3, 0.2) }
sphere lamp on box @ (0, 0.1, 0) m { radius = 2 cm }
output y = box.position.y
solve hht { dt = 1 ms, until = 0.5 s }
",
    );
    let html = temp("browser_springs.html", "");
    let o = mbd(&[
        "run",
        model.to_str().expect("path"),
        "--view",
        html.to_str().expect("path"),
        "-o",
        temp("browser_springs.csv", "").to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let dir = html.parent().expect("dir").join("chromium_springs");
    ready_without_errors(&format!("file://{}#t=0.3", html.display()), &dir);
}

#[test]
fn the_windmill_view_renders_in_chromium_and_its_blades_turn() {
    let html = temp("browser_windmill.html", "");
    let o = mbd(&[
        "run",
        "models/windmill.mbd",
        "--view",
        html.to_str().expect("path"),
        "-o",
        temp("browser_windmill.csv", "").to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let dir = html.parent().expect("dir").join("chromium");
    let url = format!("file://{}", html.display());
    ready_without_errors(&url, &dir.join("dom"));
    let shot = |t: &str, name: &str| {
        let png = html.parent().expect("dir").join(name);
        let flag = format!("--screenshot={}", png.display());
        headless(&format!("{url}#t={t}"), &[&flag], &dir.join(name));
        Pixmap::decode_png(&std::fs::read(&png).expect("screenshot")).expect("PNG")
    };
    // An eighth of a turn apart (Omega = 9.26 rad/s): the four blades as far from where they were as
    // they get.
    let (a, b) = (shot("1.0", "at_1.png"), shot("1.085", "at_2.png"));
    assert_eq!((a.width(), a.height()), (1000, 750));
    // The scene: pixels far from the background (0xf4f5f7) in the upper two thirds.
    let scene_rows = 0..(a.height() * 2 / 3);
    let far = |p: &Pixmap| {
        scene_rows
            .clone()
            .flat_map(|y| (0..p.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let c = p.pixel(x, y).expect("pixel");
                let d = (c.red() as i32 - 0xf4).abs()
                    + (c.green() as i32 - 0xf5).abs()
                    + (c.blue() as i32 - 0xf7).abs();
                d > 120
            })
            .count()
    };
    let drawn = far(&a);
    // Measured 18,183 drawn pixels.
    assert!(drawn > 6_000, "the scene looks empty: {drawn} drawn pixels");
    let moved = scene_rows
        .flat_map(|y| (0..a.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (p, q) = (a.pixel(x, y).expect("pixel"), b.pixel(x, y).expect("pixel"));
            (p.red() as i32 - q.red() as i32).abs() + (p.green() as i32 - q.green() as i32).abs()
                > 60
        })
        .count();
    // Measured 13,539 pixels changed.
    assert!(
        moved > 4_500,
        "the blades did not move between the screenshots: {moved} pixels changed"
    );
}
