"""The report's pictures and clip in headless Chromium (issue 16, items 2 and 3).

A page made of what the report embeds (its ``<video>`` markup, :func:`reports._html.video`; the
renders with the creatures; a clip from ``footfall render``) is opened in Debian's chromium: every
image loads and is not blank (drawn into a canvas by a script in the page), the video loads, has
the expected duration and size, and a frame from its middle is not blank; a screenshot of the page
is not blank either.
"""

import json
import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

CLI = [sys.executable, "-m", "footfall.cli"]
HEADLESS = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
FRAMES = 60
FPS = 30.0
SIZE = (320, 240)
CHROMIUM = shutil.which("chromium")

pytestmark = [pytest.mark.slow, pytest.mark.skipif(CHROMIUM is None, reason="Debian chromium is not installed (.ci/run installs it)")]

# For every image and video: loaded? size, and the standard deviation of its pixels (a blank one has ~0).
CHECK_SCRIPT = """<script>
function spread(source, width, height) {
  var canvas = document.createElement('canvas');
  canvas.width = width; canvas.height = height;
  var g = canvas.getContext('2d');
  g.drawImage(source, 0, 0, width, height);
  var d = g.getImageData(0, 0, width, height).data, n = d.length / 4, sum = 0, sq = 0;
  for (var i = 0; i < d.length; i += 4) { var y = (d[i] + d[i + 1] + d[i + 2]) / 3; sum += y; sq += y * y; }
  var mean = sum / n;
  return Math.sqrt(Math.max(sq / n - mean * mean, 0));
}
var report = {images: [], videos: []};
var videos = Array.prototype.slice.call(document.querySelectorAll('video'));
var pending = videos.length + 1;
function finish() {
  if (--pending > 0) return;
  var pre = document.createElement('pre');
  pre.id = 'media-check';
  pre.textContent = JSON.stringify(report);
  document.body.appendChild(pre);
}
videos.forEach(function (v) {
  var entry = {src: v.getAttribute('src')};
  report.videos.push(entry);
  function sought() {
    entry.frame_spread = spread(v, v.videoWidth, v.videoHeight);
    finish();
  }
  function loaded() {
    entry.duration = v.duration; entry.width = v.videoWidth; entry.height = v.videoHeight;
    v.pause();
    v.addEventListener('seeked', sought, {once: true});
    v.currentTime = v.duration / 2;
  }
  v.addEventListener('error', function () { entry.error = v.error ? v.error.code : 'error'; finish(); });
  if (v.readyState >= 2) loaded(); else v.addEventListener('loadeddata', loaded, {once: true});
});
window.addEventListener('load', function () {
  Array.prototype.slice.call(document.images).forEach(function (i) {
    var ok = i.complete && i.naturalWidth > 0;
    report.images.push({src: i.getAttribute('src'), loaded: ok,
                        spread: ok ? spread(i, i.naturalWidth, i.naturalHeight) : 0});
  });
  finish();
});
</script>"""


def chromium(*args, profile):
    return subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                           "--disable-background-networking", "--disable-component-update", "--disable-sync",
                           f"--user-data-dir={profile}", "--allow-file-access-from-files", *args],
                          capture_output=True, text=True, timeout=180)


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """A folder with ``index.html``: the report's video markup for a 60-frame clip and two renders."""
    from footfall.reports import _html
    from footfall.reports._animation import recording_clip_scene, render_stills

    root = tmp_path_factory.mktemp("browser")
    recording = root / "flat.npz"
    proc = subprocess.run(CLI + ["simulate", "flat", "--frames", str(FRAMES), "--record", str(recording), "--json"],
                          capture_output=True, text=True, timeout=300, env=HEADLESS)
    assert proc.returncode == 0, proc.stderr
    site = root / "site"
    proc = subprocess.run(CLI + ["render", "--recording", str(recording), "--out", str(site / "renders" / "clip.mp4"),
                                 "--width", str(SIZE[0]), "--height", str(SIZE[1])],
                          capture_output=True, text=True, timeout=300, env=HEADLESS)
    assert proc.returncode == 0, proc.stderr
    names = render_stills(recording_clip_scene(recording), site / "renders", size=SIZE)
    body = _html.video("renders/clip.mp4", "flat: the crowd walking") + "".join(
        f'<img src="renders/{n}" alt="{n}">' for n in names)
    (site / "index.html").write_text(f"<!DOCTYPE html><html><head><meta charset='utf-8'><style>{_html.STYLE}</style>"
                                     f"</head><body>{body}{CHECK_SCRIPT}</body></html>", encoding="utf-8")
    return site


def media_check(html, tmp_path) -> dict:
    """Open ``html`` (a page with :data:`CHECK_SCRIPT` in it) in Chromium; its findings as a dict.

    The page writes them once every video has been sought; on a machine busy with other work that
    can take longer than the virtual time budget, so a page that has not finished is opened again."""
    for attempt in range(3):
        proc = chromium("--virtual-time-budget=30000", "--dump-dom", html.as_uri(), profile=tmp_path / f"profile-{attempt}")
        found = re.search(r'<pre id="media-check">(.*?)</pre>', proc.stdout, re.S)
        if found:
            return json.loads(found.group(1).replace("&quot;", '"'))
    raise AssertionError((proc.returncode, proc.stderr[-2000:]))


def test_every_image_and_the_video_load_and_are_not_blank(page, tmp_path):
    report = media_check(page / "index.html", tmp_path)
    assert len(report["images"]) == 2
    for image in report["images"]:
        assert image["loaded"] and image["spread"] > 8.0, image
    (video,) = report["videos"]
    assert "error" not in video, video
    assert video["duration"] == pytest.approx(FRAMES / FPS, abs=0.05), video
    assert (video["width"], video["height"]) == SIZE
    assert video["frame_spread"] > 8.0, video


def test_a_screenshot_of_the_page_is_not_blank(page, tmp_path):
    from PIL import Image

    shot = tmp_path / "page.png"
    proc = chromium(f"--screenshot={shot}", "--window-size=700,900", "--virtual-time-budget=5000",
                    "--hide-scrollbars", (page / "index.html").as_uri(), profile=tmp_path / "profile")
    assert shot.is_file(), proc.stderr[-2000:]
    pixels = np.asarray(Image.open(shot).convert("RGB")).astype(np.float64)
    assert pixels.std() > 8.0
    assert np.unique(pixels.reshape(-1, 3), axis=0).shape[0] > 64
    # The two renders lie below the video: the lower part of the page is a picture, not the page's white.
    lower = pixels[pixels.shape[0] // 2:]
    assert (lower.min(axis=2) < 200).mean() > 0.2
