#!/usr/bin/env bash
# Part of the install_consumer test: an installed copy stands on its own.
#   check-relocated.sh PREFIX BUILD_DIR SOURCE_DIR
# Moves the installed prefix PREFIX to a scratch folder outside the build and source trees (so no
# path fixed at install time is right any more) and runs the installed rp-jointmove from there
# with no LD_LIBRARY_PATH, with the build tree and the source tree out of its reach: it runs in a
# private mount namespace (unshare) in which both folders are empty tmpfs mounts. Only that
# process sees them so; everything else on the machine, such as other tests that ctest -j runs
# from the build tree meanwhile, sees them as they are, and nothing has to be put back (a killed
# test leaves no renamed folder behind). Where no private mount namespace can be made (neither
# root nor unprivileged user namespaces), it says SKIPPED for the hiding and runs the rest.
#
# Checks, with the build and source trees hidden:
# - the program loads libroboticplatform from the moved prefix (ldd);
# - without RP_WEB_ROOT it serves the installed front end (a mark added to the installed pages),
#   its script too, not the build tree's and not the "front end not built" page;
# - with RP_WEB_ROOT naming another folder it serves that folder's pages (another mark);
# - each time it ends with status 130 (128 + SIGINT) after SIGINT, as documented;
# then once more with the build tree in reach: the installed front end is still the one served.
# And the installed Python module (if built): imported from the moved prefix, it loads the moved
# library and computes.
set -euo pipefail
prefix=$1
build=$(cd "$2" && pwd -P)
source=$(cd "$3" && pwd -P)
fail() { echo "check-relocated: $*" >&2; exit 1; }

scratch=$(mktemp -d "${TMPDIR:-/tmp}/rp-installed.XXXXXX")
scratch=$(cd "$scratch" && pwd -P)
pid=
cleanup() {
  if [[ -n $pid ]]; then kill -KILL "$pid" 2>/dev/null || true; fi
  rm -rf "$scratch"
}
trap cleanup EXIT
case "$scratch/" in
  "$build/"* | "$source/"*) fail "the scratch folder $scratch lies in the build or source tree: set TMPDIR elsewhere" ;;
esac

moved=$scratch/prefix
mv "$prefix" "$moved"
web=$moved/share/roboticplatform/web
[[ -f $web/index.html ]] || fail "the front end is not installed ($web/index.html missing)"
# The folder RP_WEB_ROOT names in the second run: a copy of the front end with a mark of its own.
other=$scratch/other-web
cp -r "$web" "$other"
mark="<!-- installed copy $$ $RANDOM -->"
for f in "$web"/*.html; do echo "$mark" >>"$f"; done
otherMark="<!-- RP_WEB_ROOT copy $$ $RANDOM -->"
for f in "$other"/*.html; do echo "$otherMark" >>"$f"; done

# The launcher: what comes after it runs with the build and source trees hidden. Mounted deepest
# first: a tmpfs over the source tree would hide a build tree inside it from the second mount.
hide=("$build")
case "$source/" in "$build/"*) ;; *) hide+=("$source") ;; esac
# shellcheck disable=SC2016  # expanded by the inner bash
hideScript='while [[ $1 != -- ]]; do mount -t tmpfs -o size=64k,mode=0755 rp-hidden "$1" || exit 97; shift; done; shift; exec "$@"'
launcher=()
for ns in "--mount" "--user --map-root-user --mount"; do
  # shellcheck disable=SC2086  # $ns is a list of options
  if unshare $ns --propagation private bash -c "$hideScript" hide "${hide[@]}" -- true 2>/dev/null; then
    # shellcheck disable=SC2206
    launcher=(unshare $ns --propagation private bash -c "$hideScript" hide "${hide[@]}" --)
    break
  fi
done
if ((${#launcher[@]})); then
  # The hiding works: in the namespace neither tree has anything in it.
  # shellcheck disable=SC2016  # expanded by the inner bash
  "${launcher[@]}" bash -c '[[ ! -e $1/CMakeCache.txt && ! -e $1/webroot && ! -e $1/lib && ! -e $2/CMakeLists.txt ]]' \
    check "$build" "$source" || fail "the build tree $build or the source tree $source is still visible in the namespace"
  [[ -e $build/CMakeCache.txt ]] || fail "the build tree is gone outside the namespace"
  echo "check-relocated: the build tree $build and the source tree $source are hidden from the installed program (private mount namespace: ${launcher[*]:0:4})"
else
  echo "check-relocated: SKIPPED hiding the build and source trees: no private mount namespace here (unshare --mount needs root or unprivileged user namespaces); the installed program runs with them in place"
fi

reach="the build and source trees in reach"
((${#launcher[@]})) && reach="the build and source trees hidden"
program=$moved/bin/rp-jointmove
# The loader finds the library through the program's run path, in the moved prefix.
lib=$("${launcher[@]}" env -u LD_LIBRARY_PATH ldd "$program" | awk '/libroboticplatform/ {print $3}')
[[ $lib == "$moved"/* ]] || fail "rp-jointmove loads libroboticplatform from '$lib', not from $moved/lib"

# The Python module, where the build has one (RP_PYTHON): imported from the moved prefix's
# dist-packages (docs/python.md) with no LD_LIBRARY_PATH, it loads libroboticplatform from the
# moved prefix through its run path and computes.
site=$(find "$moved/lib" -maxdepth 3 -type d -name roboticplatform -path '*-packages/*' | head -n 1)
if [[ -n $site ]]; then
  # shellcheck disable=SC2016  # expanded by Python
  py=$("${launcher[@]}" env -u LD_LIBRARY_PATH PYTHONPATH="${site%/roboticplatform}" /usr/bin/python3 -c '
import roboticplatform as rp
puma = rp.Puma560Model()
lib = [l.split()[-1] for l in open("/proc/self/maps") if "libroboticplatform" in l][0]
print(rp.__file__, lib, round(float(puma.fk(puma.home)[2, 3]), 5))') || fail "the installed Python module does not import"
  read -r module library z <<<"$py"
  [[ $module == "$moved"/* ]] || fail "Python imported roboticplatform from $module, not from $moved"
  [[ $library == "$moved"/* ]] || fail "the Python module loads libroboticplatform from $library, not from $moved/lib"
  [[ $z == 1.53543 ]] || fail "the installed Python module's Puma end-effector height is $z, not 1.53543"
  echo "check-relocated: the installed Python module in $site, $([[ ${#launcher[@]} -gt 0 ]] && echo "the build and source trees hidden" || echo "the trees in reach"), loads $library and computes"
else
  echo "check-relocated: no Python module installed (RP_PYTHON off): not checked"
fi

run=$scratch/run
mkdir "$run"
cd "$run" # no rp.cfg here: a simulated Puma 560

# Runs the installed rp-jointmove (environment changes for env first), fetches the page whose URL
# (with its token) it prints, checks that the page carries `expect` and not `reject`, that its
# script is the one in `root`, and that SIGINT ends the program with 130.
runs=0
serve() {
  local expect=$1 reject=$2 root=$3
  shift 3
  # Each run's output in files of its own: the redirection of the program started in the
  # background may happen after the first look at the file, which then still held the previous
  # run's URL (a fetch from a port already closed: seen once in CI). Made empty beforehand, so
  # that the first look finds a file.
  runs=$((runs + 1))
  local err=err$runs.txt
  : >"$err"
  "${launcher[@]}" env -u LD_LIBRARY_PATH "$@" "$program" -simclock -gui-address 127.0.0.1 -gui-port 0 \
    -gui-token "rp$$" >"out$runs.txt" 2>"$err" &
  pid=$!
  local url=
  for _ in $(seq 600); do # up to 60 s on a loaded machine
    url=$(sed -n 's/^rp: Scene Viewer at \(http[^ ]*\).*/\1/p' "$err" | head -n 1)
    [[ -n $url ]] && break
    if ! kill -0 "$pid" 2>/dev/null; then
      local rc=0
      wait "$pid" || rc=$?
      pid=
      cat "$err" >&2
      fail "rp-jointmove exited ($rc) before serving its page"
    fi
    sleep 0.1
  done
  [[ -n $url ]] || { cat "$err" >&2; fail "rp-jointmove printed no Scene Viewer URL"; }
  [[ $url == *"token=rp$$" ]] || fail "the printed URL does not carry the token: $url"
  local page
  page=$(curl --silent --show-error --fail --max-time 30 "$url") || fail "cannot fetch $url"
  grep -qF "$expect" <<<"$page" || fail "the page served is not the front end of $root:
$page"
  grep -qF "$reject" <<<"$page" && fail "the page served is the one RP_WEB_ROOT does not name"
  grep -q '<script type="module"' <<<"$page" || fail "the page served has no script: not the built front end"
  grep -q 'not built' <<<"$page" && fail "the server answered with its \"front end not built\" page"
  # A script of the page comes from the same folder.
  local script base
  script=$(grep -o 'src="[^"]*\.js"' <<<"$page" | head -n 1 | sed 's/src="\/*//; s/"$//')
  [[ -n $script ]] || fail "the page names no script"
  base=${url%%\?*}
  base=${base%/*}
  curl --silent --show-error --fail --max-time 30 "$base/$script" | cmp -s - "$root/$script" ||
    fail "the script $script served differs from $root/$script"
  kill -INT "$pid"
  local rc=0
  wait "$pid" || rc=$?
  pid=
  [[ $rc -eq 130 ]] || { cat "$err" >&2; fail "rp-jointmove ended with status $rc after SIGINT, not 130"; }
  echo "check-relocated: the installed rp-jointmove in $moved, $reach, served $root ($url) and ended with 130 after SIGINT"
}

serve "$mark" "$otherMark" "$web" -u RP_WEB_ROOT
serve "$otherMark" "$mark" "$other" RP_WEB_ROOT="$other"
# And with the build tree in reach: the installed copy is still the one served (before, an
# installed program served the build tree's front end).
if ((${#launcher[@]})); then
  launcher=()
  reach="the build and source trees in reach"
  serve "$mark" "$otherMark" "$web" -u RP_WEB_ROOT
fi
