#!/usr/bin/env bash
# Opens report pages in headless Chromium and checks that they render and that every picture
# loads: each <img> has naturalWidth > 0 and each inline <svg> has a size on the page.
#   check_pages_chromium.sh PAGE.html...   check these pages
#   check_pages_chromium.sh                make a remesh page with $MRSNAKE_BIN and check it
# Exit 77 (ctest: skipped) when chromium is not installed. Set SCREENSHOT_DIR to also save a
# full-page screenshot of each page there.
set -euo pipefail
browser="$(command -v chromium || command -v chromium-browser || true)"
if [ -z "$browser" ]; then
  echo "SKIP: chromium is not installed (scripts/setup installs Debian's chromium); pages not checked in a browser"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
pages=("$@")
if [ ${#pages[@]} -eq 0 ]; then
  : "${MRSNAKE_BIN:?MRSNAKE_BIN is not set; run through ctest or pass page paths}"
  "$MRSNAKE_BIN" --quiet synth --shape ellipsoid --size 32 --noise none -o "$work/case" >/dev/null
  "$MRSNAKE_BIN" --quiet mc --labels "$work/case/truth.nii.gz" --label 1 --smooth 20 -o "$work/case/mc.vtp" >/dev/null
  "$MRSNAKE_BIN" --quiet remesh "$work/case/mc.vtp" -o "$work/remesh" --faces 2048 --compare-unrelaxed >/dev/null
  "$MRSNAKE_BIN" --quiet build-model --labels "$work/case/truth.nii.gz" --label 1 --faces 2048 -o "$work/case.model" >/dev/null
  pages=("$work/remesh/report.html" "$work/case.model/report.html")
fi

chrome() {
  local profile
  profile="$(mktemp -d "$work/profile.XXXX")"
  timeout 120 "$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$profile" "$@" 2>"$work/chromium.log"
}

failed=0
for page in "${pages[@]}"; do
  [ -f "$page" ] || { echo "FAIL: $page does not exist"; failed=1; continue; }
  # A copy of the page with a script that writes its findings into the DOM once it has loaded.
  probe="$work/probe.html"
  sed 's#</body>#<script>window.addEventListener("load",function(){var i=document.images,ok=0,bad=[];for(var k=0;k<i.length;k++){if(i[k].complete\&\&i[k].naturalWidth>0)ok++;else bad.push(i[k].alt);}var s=document.querySelectorAll("svg"),sok=0;for(var k=0;k<s.length;k++){var r=s[k].getBoundingClientRect();if(r.width>0\&\&r.height>0)sok++;}var d=document.createElement("pre");d.id="mrsnake-check";d.textContent="CHE"+"CK images="+i.length+" loaded="+ok+" svgs="+s.length+" drawn="+sok+" height="+document.body.scrollHeight+" bad="+bad.join("|");document.body.appendChild(d);});</script></body>#' \
    "$page" >"$probe"
  dom="$(chrome --window-size=1400,1000 --virtual-time-budget=10000 --dump-dom "file://$probe" || true)"
  line="$(grep -o 'CHECK images=[0-9][^<]*' <<<"$dom" || true)"
  if [ -z "$line" ]; then
    echo "FAIL: $page did not render in chromium (no result from the probe script)"
    tail -5 "$work/chromium.log"
    failed=1
    continue
  fi
  echo "$page: $line"
  read -r images loaded svgs drawn height <<<"$(sed -E 's/CHECK images=([0-9]+) loaded=([0-9]+) svgs=([0-9]+) drawn=([0-9]+) height=([0-9]+).*/\1 \2 \3 \4 \5/' <<<"$line")"
  if [ "$images" != "$loaded" ]; then echo "FAIL: $page: $((images - loaded)) of $images images did not load"; failed=1; fi
  if [ "$svgs" != "$drawn" ]; then echo "FAIL: $page: $((svgs - drawn)) of $svgs SVG charts have no size"; failed=1; fi
  if [ "$svgs" -eq 0 ] && [ "$images" -eq 0 ]; then echo "FAIL: $page has no pictures at all"; failed=1; fi
  if [ "$height" -lt 300 ]; then echo "FAIL: $page is only $height px tall"; failed=1; fi
  if [ "$images" -eq 0 ] && ! grep -q "class='note'" "$page"; then
    echo "FAIL: $page has no 3D render and no note saying why"; failed=1
  fi
  if [ -n "${SCREENSHOT_DIR:-}" ]; then
    mkdir -p "$SCREENSHOT_DIR"
    shot="$SCREENSHOT_DIR/$(basename "$(dirname "$page")")-$(basename "$page" .html).png"
    chrome --hide-scrollbars --window-size=1400,"$((height + 40))" --screenshot="$shot" "file://$page" >/dev/null || true
    echo "screenshot: $shot"
  fi
done
[ "$failed" -eq 0 ] && echo "chromium: all pages render and every picture loads"
exit "$failed"
