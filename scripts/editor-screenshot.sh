#!/usr/bin/env bash
# The editor screenshots: Neovim (Debian's 0.7) in an xterm under Xvfb, its LSP client on
# `psysc lsp`, captured with xwd (ffmpeg makes it a PNG).
#   bash scripts/editor-screenshot.sh [OUT.png]
#     editor-support/README.md's: a hover, inlay types (editor-support/neovim/inlay_hints.lua)
#     and the quick fix of a typo
#   bash scripts/editor-screenshot.sh --rename [OUT.png]
#     docs/images/neovim_rename.png: `lift` renamed to `rise` from main.psys, in main.psys and
#     in lib.psys beside it and in marbles.psys, which was never opened (none saved)
#     (the workspace index); each file's diagnostics clean
# (after the build; PSYSC= another psysc)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
psysc=$(realpath "${PSYSC:-$root/build/tools/psysc/psysc}")
scene=hover
if [ "${1:-}" = --rename ]; then scene=rename; shift; fi
default=$root/editor-support/images/neovim.png
[ $scene = rename ] && default=$root/docs/images/neovim_rename.png
out=$(realpath -m "${1:-$default}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lua" "$(dirname "$out")"
cp "$root/editor-support/neovim/inlay_hints.lua" "$work/lua/psys_inlay_hints.lua"

cat > "$work/fireworks.psys" <<'PSYS'
// A rocket that trails sparks; `pso` is a typo for `pos`.
extern sparks: float = 50;

fn gravity(m: float) -> vec3 = vec3(0, -9.82 * m, 0);

object spark(ipos: vec3) {
    pos = snapshot(ipos) + integrate(vel);
    vel = origin + integrate(gravity(0.4));
    point(pos, mix(green, black, age), 2);
    kill when age > 1;
}

@integrator(rk4)
object rocket(ivel: vec3) {
    pos = origin + integrate(vel);
    vel = snapshot(ivel) + integrate(gravity(0.3));
    point(pso, white, 2);
    emit spark(pos) at sparks per second;
    kill when vel.y < 0;
}

spawn rocket(vec3(0, 15, 0));
PSYS

cat > "$work/init.lua" <<LUA
vim.opt.runtimepath:prepend("$root/editor-support/vim")
vim.opt.runtimepath:prepend("$work")
vim.cmd("filetype plugin indent on | syntax on")
vim.opt.termguicolors = true
vim.cmd("colorscheme default | set background=dark number signcolumn=yes laststatus=2 noshowmode")
vim.lsp.handlers["textDocument/hover"] = vim.lsp.with(vim.lsp.handlers.hover, { border = "rounded" })
vim.api.nvim_create_autocmd("FileType", {
  pattern = "psys",
  callback = function(args)
    local id = vim.lsp.start_client({ name = "psysc", cmd = { "$psysc", "lsp", "--debounce", "0" }, root_dir = "$work" })
    vim.lsp.buf_attach_client(args.buf, id)
    vim.wait(5000, function() local c = vim.lsp.get_client_by_id(id) return c and c.initialized end, 20)
    require("psys_inlay_hints").attach(args.buf, id)
  end,
})
-- Once the diagnostics are in: the cursor on the typo's line, at \`white\`; its hover;
-- then the quick fixes of the line, as the user's key asks for them.
vim.defer_fn(function()
  vim.api.nvim_win_set_cursor(0, { 17, 15 })
  vim.lsp.buf.hover()
  vim.defer_fn(function() vim.lsp.buf.code_action() end, 800)
end, 2000)
LUA

if [ $scene = rename ]; then
  cat > "$work/lib.psys" <<'PSYS'
// Forces the effects here share.
fn lift(h: float) -> vec3 = vec3(0, h, 0);
PSYS
  cat > "$work/main.psys" <<'PSYS'
import "lib.psys";

object balloon {
    pos = origin + integrate(vel);
    vel = integrate(lift(2) - vel * 0.5);
    point(pos, red, 4);
    kill when age > 4;
}

spawn balloon;
PSYS
  cat > "$work/marbles.psys" <<'PSYS'
import "lib.psys";
const hop = lift(0.5).y;
PSYS
  cat > "$work/init.lua" <<LUA
vim.opt.runtimepath:prepend("$root/editor-support/vim")
vim.cmd("filetype plugin indent on | syntax on")
vim.opt.termguicolors = true
vim.o.hidden = true
vim.cmd("colorscheme default | set background=dark number signcolumn=yes laststatus=2 noshowmode")
local id
vim.api.nvim_create_autocmd("FileType", {
  pattern = "psys",
  callback = function(args)
    id = id or vim.lsp.start_client({ name = "psysc", cmd = { "$psysc", "lsp", "--debounce", "0" }, root_dir = "$work" })
    vim.lsp.buf_attach_client(args.buf, id)
  end,
})
-- lib on the left, main on the right; the cursor on main's call of lift, renamed to rise
-- as :lua vim.lsp.buf.rename("rise") does; then marbles.psys (never opened: the rename
-- edited it) below lib, to show it.
vim.defer_fn(function()
  vim.cmd("leftabove vsplit $work/lib.psys | wincmd l")
  vim.api.nvim_win_set_cursor(0, { 5, 20 })
  vim.lsp.buf.rename("rise")
  vim.defer_fn(function()
    vim.cmd("wincmd h | split $work/marbles.psys | wincmd l")
    vim.api.nvim_echo({ { "renamed lift → rise in 3 files, none saved: marbles.psys was never opened" } }, false, {})
  end, 1200)
end, 2500)
LUA
  target=main.psys
else
  target=fireworks.psys
fi

xvfb-run -a -s "-screen 0 1200x800x24" bash -c "
  xterm -T psys-nvim -geometry 104x30 -fa 'DejaVu Sans Mono' -fs 12 -bg '#1e1e1e' -fg '#d4d4d4' \
    -e nvim -u '$work/init.lua' -i NONE '$work/$target' &
  sleep 6
  xwd -name psys-nvim -silent -out '$work/shot.xwd'
  ffmpeg -loglevel error -y -i '$work/shot.xwd' '$out'
  kill %1 2>/dev/null || true
"
echo "wrote $out"
