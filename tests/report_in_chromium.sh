#!/usr/bin/env bash
# The HTML report of `pcsg verify --report`, opened in headless Chromium: every page of it
# loads and shows all its images, its links lead to pages that exist, it asks for nothing
# outside the report directory, and a screenshot of the index is not blank.
#
#   usage: report_in_chromium.sh PCSG SCENE...
#
# The report is written, then moved to another directory before it is checked, so any
# absolute path in it would show. The report's <img> tags mark themselves from inline
# onload/onerror handlers (data-state="loaded" with data-natural="WxH", or
# data-state="broken"); Chromium's --dump-dom prints the DOM after they ran. The checker
# must be able to fail: it is also run on a copy of the report with one image deleted,
# and on a blank screenshot, and has to reject both.
#
# Exit status: 0 passed, 1 failed, 77 skipped because chromium is not installed (ctest's
# SKIP_RETURN_CODE).
set -uo pipefail
pcsg=$1
shift
scenes=("$@")

chromium=$(command -v chromium || command -v chromium-browser || true)
if [[ -z $chromium ]]; then
    echo "SKIPPED: chromium is not installed (apt-get install chromium), so the report cannot be opened"
    exit 77
fi
if ! command -v oiiotool >/dev/null; then
    echo "FAILED: oiiotool is not installed (apt-get install openimageio-tools)" >&2
    exit 1
fi

work=$(mktemp -d /tmp/pcsg-report-test-XXXXXX)
trap 'rm -rf "$work"' EXIT

# chrome ARGS...: headless Chromium with a profile of its own, nothing from the network.
chrome() {
    local profile
    profile=$(mktemp -d "$work/profile-XXXXXX")
    timeout 120 "$chromium" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
        --disable-background-networking --disable-component-update --disable-sync \
        --disable-extensions --hide-scrollbars --user-data-dir="$profile" \
        --virtual-time-budget=5000 "$@" 2>>"$work/chromium.log"
    local status=$?
    rm -rf "$profile"
    return $status
}

# check_page FILE: prints one line per problem with the page; status 1 when there is any.
check_page() {
    local page=$1 dir dom problems=0 imgs tag src state natural href
    dir=$(dirname "$page")
    if ! dom=$(chrome --dump-dom "file://$page") || [[ $dom != *"</html>"* ]]; then
        echo "$page: Chromium could not load the page"
        return 1
    fi
    imgs=$(grep -o '<img [^>]*>' <<<"$dom")
    if [[ -z $imgs ]]; then
        echo "$page: no images on the page"
        return 1
    fi
    while IFS= read -r tag; do
        src=$(sed -n 's/.* src="\([^"]*\)".*/\1/p' <<<"$tag")
        state=$(sed -n 's/.* data-state="\([^"]*\)".*/\1/p' <<<"$tag")
        natural=$(sed -n 's/.* data-natural="\([^"]*\)".*/\1/p' <<<"$tag")
        if [[ $state == broken ]]; then
            echo "$page: image $src is broken"
            problems=1
        elif [[ $state != loaded ]]; then
            echo "$page: image $src did not finish loading (no onload mark: '$tag')"
            problems=1
        elif ! [[ $natural =~ ^[1-9][0-9]*x[1-9][0-9]*$ ]]; then
            echo "$page: image $src loaded with natural size '$natural'"
            problems=1
        fi
    done <<<"$imgs"
    # Links and sources stay inside the report: relative, and to files that exist.
    while IFS= read -r href; do
        [[ -z $href ]] && continue
        if [[ $href == *:* || $href == /* ]]; then
            echo "$page: link or source outside the report: $href"
            problems=1
        elif [[ ! -e $dir/${href%%#*} ]]; then
            echo "$page: link to a missing file: $href"
            problems=1
        fi
    done < <(grep -o -E '(href|src)="[^"]*"' <<<"$dom" | sed -E 's/^[a-z]+="(.*)"$/\1/')
    return $problems
}

# check_report DIR: the index and every scene page it links to.
check_report() {
    local root=$1 problems=0 pages page
    [[ -f $root/index.html ]] || { echo "$root: no index.html"; return 1; }
    check_page "$root/index.html" || problems=1
    pages=$(grep -o 'href="[^"]*/index.html"' "$root/index.html" | sed 's/^href="//; s/"$//' | sort -u)
    if [[ -z $pages ]]; then
        echo "$root/index.html: links to no scene page"
        return 1
    fi
    for page in $pages; do
        check_page "$root/$page" || problems=1
        # ... and each scene page links back to the index.
        grep -q 'href="../index.html"' "$root/$page" ||
            { echo "$root/$page: no link back to the index"; problems=1; }
    done
    return $problems
}

# check_screenshot PNG: the picture is not one colour, and the page's background does not
# cover 95% of it: something was drawn (the index of two scenes leaves about 85%; whether
# the images themselves show is check_page's job).
check_screenshot() {
    local png=$1 stats width height background
    stats=$(oiiotool --stats "$png" 2>&1) || { echo "$png: cannot read: $stats"; return 1; }
    if grep -q 'Constant: Yes' <<<"$stats"; then
        echo "$png: the screenshot is blank (one colour)"
        return 1
    fi
    read -r width height < <(oiiotool --info "$png" | sed -E 's/.*: *([0-9]+) x +([0-9]+),.*/\1 \2/')
    # #fafafa, the report's background.
    # oiiotool prints "  COUNT  COLOUR".
    background=$(oiiotool "$png" --colorcount "0.98039,0.98039,0.98039" 2>&1 |
        awk '$1 ~ /^[0-9]+$/ { print $1; exit }')
    if [[ -z $background || -z $width ]]; then
        echo "$png: cannot count its background pixels"
        return 1
    fi
    if ((background * 100 > width * height * 95)); then
        echo "$png: $background of $((width * height)) pixels are background: nearly blank"
        return 1
    fi
    echo "$png: ${width}x$height, $((100 * background / (width * height)))% background"
}

failed=0
fail() { echo "FAILED: $*"; failed=1; }

echo "== writing the report of ${scenes[*]}"
"$pcsg" verify "${scenes[@]}" --width 64 --height 48 --threads 2 --report "$work/written"
status=$?
((status <= 1)) || { fail "pcsg verify could not run (exit status $status)"; exit 1; }
mv "$work/written" "$work/report"   # relative links only: the report still works

echo "== the report in Chromium"
if check_report "$work/report"; then
    echo "every page loads and shows all its images; every link resolves"
else
    fail "the report does not check"
fi
pages=$(find "$work/report" -name index.html | wc -l)
((pages == ${#scenes[@]} + 1)) || fail "$pages pages, expected an index and ${#scenes[@]} scene page(s)"

echo "== a screenshot of the index"
chrome --window-size=1280,900 --screenshot="$work/index.png" "file://$work/report/index.html" >/dev/null
if [[ -f $work/index.png ]]; then
    check_screenshot "$work/index.png" || fail "the screenshot of the index"
else
    fail "Chromium wrote no screenshot"
fi

echo "== the checker can fail: a report with one image deleted"
cp -r "$work/report" "$work/damaged"
victim=$(find "$work/damaged" -name native.png | sort | tail -1)
rm "$victim"
scene_dir=$(basename "$(dirname "$victim")")
if out=$(check_page "$work/damaged/index.html"); then
    fail "the checker accepted an index whose image $scene_dir/native.png is deleted"
else
    echo "$out"
    grep -q "image $scene_dir/native.png is broken" <<<"$out" ||
        fail "the checker did not name $scene_dir/native.png as broken"
fi

echo "== the checker can fail: a blank screenshot"
oiiotool --pattern constant:color=0.98039,0.98039,0.98039 1280x900 3 -d uint8 -o "$work/blank.png"
if check_screenshot "$work/blank.png"; then
    fail "the checker accepted a blank screenshot"
fi

if ((failed)); then
    echo "--- Chromium's messages:"
    tail -20 "$work/chromium.log"
    exit 1
fi
echo "report_in_chromium: ok"
