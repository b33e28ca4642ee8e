#!/usr/bin/env bash
# make readme-check: runs the commands of README.md's code blocks, as a user would after the two
# set-up commands (`make demo`, `make test`), so that the README cannot drift from what works.
# The blocks are taken from README.md itself; the HTML comment on the line before a block says how:
#   <!-- check -->             run it; it must exit 0
#   <!-- check: background --> start it (its own process group); it must still be running after
#                              $README_CHECK_WAIT s; it is stopped (SIGINT) at the next
#                              <!-- check: stop --> or at the end
#   <!-- check: stop -->       (no block) stop the background commands started so far
#   <!-- check: file NAME -->  the block's text is written to NAME (a config file shown in full)
#   <!-- check: skip REASON --> not run here; the reason (what covers it instead) is printed
# Every other code block (output samples, file formats, the set-up commands) is not a command to
# check. The blocks run in one bash session, in order, in the repository itself (as a user runs
# them: a mirror made of symlinks would hide path effects, e.g. rosrun ignoring <package>/build/);
# what they create there (files and folders git did not list before) is removed afterwards. HOME
# and ROS_HOME are a scratch directory, and ROS uses a master on a free port.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
readme=${README_CHECK_FILE:-$root/README.md}   # another file: to test this checker
wait_s=${README_CHECK_WAIT:-12}
for need in "$root/build/devel/setup.bash" "$root/demo_output/scenario.bag"; do
  [ -e "$need" ] || { echo "readme-check: $need missing: run make test and make demo first" >&2; exit 1; }
done

work=$(mktemp -d "${TMPDIR:-/tmp}/wavog_readme_check.XXXXXX")
untracked() { git -C "$root" status --porcelain --ignored | sed -n 's/^\(??\|!!\) //p' | sort; }
untracked >"$work/before.txt"
remove_outputs() {
  untracked | comm -13 "$work/before.txt" - | while read -r path; do rm -rf "${root:?}/$path"; done
}
script=$work/commands.sh

# The README's blocks become one script: each block in a function-free section with a banner.
/usr/bin/python3 - "$readme" "$script" "$wait_s" <<'PY'
import re, shlex, sys
readme, out, wait_s = sys.argv[1], sys.argv[2], sys.argv[3]
lines = open(readme).read().split("\n")
parts, n_run, n_bg, n_skip = [], 0, 0, 0
i = 0
while i < len(lines):
    m = re.match(r"\s*<!--\s*check(?::\s*(\w+)\s*(.*?))?\s*-->\s*$", lines[i])
    if not m:
        i += 1
        continue
    mode, reason = (m.group(1) or "run"), m.group(2) or ""
    if mode == "stop":
        parts.append("readme_stop")
        i += 1
        continue
    j = i + 1
    if j >= len(lines) or not lines[j].startswith("```"):
        sys.exit(f"README.md:{i + 1}: a check marker must be followed by a code block")
    k = j + 1
    while k < len(lines) and not lines[k].startswith("```"):
        k += 1
    body = "\n".join(lines[j + 1:k])
    where = f"README.md:{j + 2}"
    if mode == "skip":
        n_skip += 1
        parts.append(f"echo {shlex.quote(f'readme-check: {where}: skipped ({reason})')}")
    elif mode == "file":
        parts.append(f"printf '%s\\n' {shlex.quote(body)} > {shlex.quote(reason)}")
    elif mode == "background":
        n_bg += 1
        parts.append(f"readme_background {shlex.quote(where)} {shlex.quote(body)}")
    elif mode == "run":
        n_run += 1
        parts.append(f"readme_banner {shlex.quote(where)}\nreadme_capture\n{body}\nreadme_ok {shlex.quote(where)}")
    else:
        sys.exit(f"README.md:{i + 1}: unknown check mode '{mode}'")
    i = k + 1
with open(out, "w") as f:
    f.write("\n".join(parts) + "\nreadme_stop\n")
print(f"readme-check: {n_run} blocks to run, {n_bg} in the background, {n_skip} skipped")
PY

port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
cd "$root"
env -i HOME="$work" PATH=/usr/bin:/bin TERM=dumb ROS_HOME="$work/ros_home" \
  ROS_MASTER_URI="http://localhost:$port" ROS_HOSTNAME=localhost WAIT_S="$wait_s" \
  bash -c '
set -eo pipefail
set -m   # background blocks get their own process group, and SIGINT reaches them
bg_pids=()
readme_banner() { echo; echo "readme-check: ---- $1"; current=$1; }
# A block runs in this shell (its cd, source and variables stay) with its output in a file, shown
# afterwards; a service answering "success: False" fails it like a non-zero exit.
readme_capture() { exec 4>&1 5>&2 >"$HOME/block.log" 2>&1; capturing=1; }
readme_ok() {
  exec 1>&4 2>&5; capturing=
  cat "$HOME/block.log"
  if grep -q "^success: False" "$HOME/block.log"; then echo "readme-check: $1: a service failed"; exit 1; fi
  echo "readme-check: $1: ok"
  current=
}
on_exit() {
  status=$?
  if [ "$status" -ne 0 ] && [ -n "${current:-}" ]; then
    if [ -n "${capturing:-}" ]; then exec 1>&4 2>&5; cat "$HOME/block.log"; fi
    echo "readme-check: $current: failed (status $status)"
  fi
  readme_stop
}
readme_background() {
  readme_banner "$1 (background)"
  bash -c "set +u; $2" >"$HOME/bg_$$_${#bg_pids[@]}.log" 2>&1 &
  local pid=$!
  bg_pids+=("$pid")
  sleep "$WAIT_S"
  if ! kill -0 "$pid" 2>/dev/null; then
    cat "$HOME/bg_$$_$((${#bg_pids[@]} - 1)).log"; echo "readme-check: $1: ended early"; exit 1
  fi
  echo "readme-check: $1: running after $WAIT_S s"
  current=
}
readme_stop() {
  for p in "${bg_pids[@]}"; do kill -INT -- "-$p" 2>/dev/null || true; done
  for p in "${bg_pids[@]}"; do wait "$p" 2>/dev/null || true; done
  bg_pids=()
}
trap on_exit EXIT
source "'"$script"'"
' && status=0 || status=$?
remove_outputs
if [ "$status" -eq 0 ]; then
  echo "readme-check: every checked README command worked"
  rm -rf "$work"
else
  echo "readme-check: FAILED (status $status); scratch directory kept: $work"
fi
exit "$status"
