#!/usr/bin/env bash
# Times README's first command on a bare Debian 12: a minimal bookworm (debootstrap
# --variant=minbase, the usual sources: bookworm, -updates, -security), this clone's
# commit copied in, `bash scripts/demo.sh` run in a chroot (/proc, /sys and /dev bound;
# no package, no compiler cache, no display). Root only; the bare system is made once in
# ROOT.tar and unpacked afresh for every run. docs/performance.md has its figures.
#   sudo bash scripts/bare-demo.sh [COMMIT]     # default: HEAD; the log: ROOT/demo.log
set -euo pipefail
cd "$(dirname "$0")/.."
rev=${1:-HEAD}
root=${PSYS_BARE_ROOT:-/var/tmp/psys-bare}
command -v debootstrap >/dev/null || apt-get install -y -q debootstrap
if [ ! -f "$root.tar" ]; then
  rm -rf "$root"
  debootstrap --variant=minbase bookworm "$root" http://deb.debian.org/debian
  rm -f "$root/etc/apt/sources.list"
  cat > "$root/etc/apt/sources.list.d/debian.sources" <<'SOURCES'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
  tar -C "$(dirname "$root")" -cf "$root.tar" "$(basename "$root")"
fi
unmount() { for m in proc sys dev; do umount -l "$root/$m" 2>/dev/null || true; done; }
unmount
rm -rf "$root" && tar -C "$(dirname "$root")" -xf "$root.tar"
cp /etc/resolv.conf "$root/etc/"
git clone -q . "$root/root/psys" && git -C "$root/root/psys" checkout -q "$(git rev-parse "$rev")"
trap unmount EXIT
for m in proc sys dev; do mount --bind "/$m" "$root/$m"; done
start=$EPOCHREALTIME
status=0
chroot "$root" env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin TERM=dumb \
  bash -c 'cd /root/psys && bash scripts/demo.sh' > "$root/demo.log" 2>&1 || status=$?
sed -n '/^== stage times/,$p' "$root/demo.log"
awk -v a="$start" -v b="$EPOCHREALTIME" -v s=$status \
  'BEGIN { printf "bare Debian 12: scripts/demo.sh %s in %.1f s (log: '"$root"'/demo.log)\n", s ? "failed" : "passed", b - a }'
exit $status
