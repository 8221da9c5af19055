" `:make` on a .psys file runs psysc check (compiler/psys.vim) and fills the quickfix list:
" the error's file, line, column, type and message; the caret lines are not entries.
" Run: PSYSC=… PSYS_VIM_OUT=… vim -Nu NONE -i NONE -n -es -S tests/editor/vim_make.vim (from the repository root).
set runtimepath^=editor-support/vim
filetype plugin on
let s:failures = []
let s:report = []

function! s:Make(file) abort
  execute 'edit' a:file
  " The psysc just built, not one on PATH.
  let &l:makeprg = substitute(&l:makeprg, '^psysc', escape($PSYSC, ' \'), '')
  silent make
  let list = filter(getqflist(), 'v:val.valid')
  call add(s:report, a:file . ': ' . string(map(copy(list), '[v:val.lnum, v:val.col, v:val.type, v:val.text]')))
  return list
endfunction

function! s:Expect(ok, what) abort
  if !a:ok
    call add(s:failures, a:what)
  endif
endfunction

let errors = s:Make('tests/errors/unknown_function.psys')
call s:Expect(&l:makeprg =~# 'check --color=never', 'makeprg runs psysc check: ' . &l:makeprg)
call s:Expect(len(errors) == 1, 'one entry for one error, got ' . len(errors))
if len(errors) >= 1
  call s:Expect(errors[0].lnum == 3 && errors[0].col == 9, 'the error is at 3:9')
  call s:Expect(errors[0].type ==# 'e', 'the entry is an error')
  call s:Expect(errors[0].text =~# 'unknown function `sinn`; did you mean `sin`?', 'the message: ' . errors[0].text)
  call s:Expect(bufname(errors[0].bufnr) =~# 'unknown_function.psys$', 'the entry names the file')
endif
let warnings = s:Make('tests/errors/integrator_unstable_decay.psys')
call s:Expect(len(warnings) == 2 && warnings[0].type ==# 'w' && warnings[1].lnum == 11, 'two warnings, the second on line 11')
let noted = s:Make('tests/errors/attribute_unknown.psys')
call s:Expect(len(noted) == 2 && noted[0].type ==# 'e' && noted[1].type ==# 'n' && noted[1].text =~# '^the attributes are',
            \ 'an error and its note')
let clean = s:Make('samples/fireworks.psys')
call s:Expect(empty(clean), 'a clean file leaves the list empty')

call writefile(s:report + map(copy(s:failures), '"FAIL: " . v:val'), $PSYS_VIM_OUT)
if empty(s:failures)
  qall!
endif
cquit!
