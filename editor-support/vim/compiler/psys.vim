" :make checks the current file with psysc and fills the quickfix list with its errors,
" warnings and notes (psysc prints `file:line:column: error: message`, then the source
" line and a caret, which are skipped).
if exists('current_compiler')
  finish
endif
let current_compiler = 'psys'

if exists(':CompilerSet') != 2
  command -nargs=* CompilerSet setlocal <args>
endif

CompilerSet makeprg=psysc\ check\ --color=never\ %:S
CompilerSet errorformat=%f:%l:%c:\ %trror:\ %m,%f:%l:%c:\ %tarning:\ %m,%f:%l:%c:\ %tote:\ %m,psysc:\ %trror:\ %m,%-G%.%#
