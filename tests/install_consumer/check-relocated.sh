#!/usr/bin/env bash
# Part of the install_consumer test: an installed copy stands on its own. Moves the installed
# prefix PREFIX to a new place MOVED (so no path fixed at install time is right any more), marks
# the installed front end, then runs the installed rp-jointmove with no LD_LIBRARY_PATH, fetches
# the page whose URL (with its token) the program prints and checks it is the installed front end
# (the mark added to its pages), not the build tree's and not the "front end not built" page. Stops the program with
# SIGINT and checks it ends as documented (exit status 130 = 128 + SIGINT).
set -euo pipefail
prefix=$1
moved=$2
fail() { echo "check-relocated: $*" >&2; exit 1; }

rm -rf "$moved"
mv "$prefix" "$moved"
web=$moved/share/roboticplatform/web
[[ -f $web/index.html ]] || fail "the front end is not installed ($web/index.html missing)"
mark="<!-- installed copy $$ $RANDOM -->"
for f in "$web"/*.html; do echo "$mark" >>"$f"; done

program=$moved/bin/rp-jointmove
# The loader finds the library through the program's run path, in the moved prefix.
lib=$(env -u LD_LIBRARY_PATH ldd "$program" | awk '/libroboticplatform/ {print $3}')
[[ $lib == "$moved"/* ]] || fail "rp-jointmove loads libroboticplatform from '$lib', not from $moved/lib"

run=$(mktemp -d)
trap 'kill -KILL "$pid" 2>/dev/null || true; rm -rf "$run"' EXIT
cd "$run"   # no rp.cfg here: a simulated Puma 560
env -u LD_LIBRARY_PATH -u RP_WEB_ROOT "$program" -simclock -gui-address 127.0.0.1 -gui-port 0 -gui-token "rp$$" >out.txt 2>err.txt &
pid=$!
url=
for _ in $(seq 600); do   # up to 60 s on a loaded machine
  url=$(sed -n 's/^rp: Scene Viewer at \(http[^ ]*\).*/\1/p' err.txt | head -n 1)
  [[ -n $url ]] && break
  kill -0 "$pid" 2>/dev/null || { wait "$pid" && rc=0 || rc=$?; cat err.txt >&2; fail "rp-jointmove exited ($rc) before serving its page"; }
  sleep 0.1
done
[[ -n $url ]] || { cat err.txt >&2; fail "rp-jointmove printed no Scene Viewer URL"; }
[[ $url == *"token=rp$$" ]] || fail "the printed URL does not carry the token: $url"
page=$(curl --silent --show-error --fail --max-time 30 "$url") || fail "cannot fetch $url"
grep -qF "$mark" <<<"$page" || fail "the page served is not the installed front end of $web:
$page"
grep -q '<script type="module"' <<<"$page" || fail "the page served has no script: not the built front end"
grep -q 'not built' <<<"$page" && fail "the server answered with its \"front end not built\" page"
# A script of the page comes from the installed copy too.
script=$(grep -o 'src="[^"]*\.js"' <<<"$page" | head -n 1 | sed 's/src="\/*//; s/"$//')
[[ -n $script ]] || fail "the page names no script"
root=${url%%\?*}
root=${root%/*}
curl --silent --show-error --fail --max-time 30 "$root/$script" | cmp -s - "$web/$script" ||
  fail "the script $script served differs from the installed $web/$script"
kill -INT "$pid"
rc=0
wait "$pid" || rc=$?
[[ $rc -eq 130 ]] || { cat err.txt >&2; fail "rp-jointmove ended with status $rc after SIGINT, not 130"; }
echo "check-relocated: the installed rp-jointmove in $moved served its installed front end ($url) and ended with 130 after SIGINT"
