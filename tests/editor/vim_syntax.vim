" Checks the syntax groups vim gives known places of a sample and of the showcase file.
" Run: vim -Nu NONE -i NONE -n -es -S tests/editor/vim_syntax.vim -c 'qa!' (from the repository root);
" it writes what it found to $PSYS_VIM_OUT and exits with an error if any place is wrong.
set runtimepath^=editor-support/vim
filetype plugin indent on
syntax on
let s:failures = []
let s:report = []

" The syntax group at the `nth` match of `needle` (very nomagic) on the line that matches `line`.
function! s:Check(line, needle, group) abort
  call cursor(1, 1)
  let l = search('\V' . a:line, 'cW')
  if l == 0
    call add(s:failures, 'no line ' . a:line)
    return
  endif
  let c = stridx(getline(l), a:needle) + 1
  let got = synIDattr(synID(l, c, 1), 'name')
  call add(s:report, printf('%s:%d:%d %s -> %s', expand('%:t'), l, c, a:needle, got))
  if got !=# a:group
    call add(s:failures, printf('%s line %d `%s`: expected %s, got %s', expand('%:t'), l, a:needle, a:group, got))
  endif
endfunction

edit samples/fireworks.psys
if &filetype !=# 'psys'
  call add(s:failures, 'ftdetect: filetype is "' . &filetype . '"')
endif
call s:Check('// Thesis', 'Thesis', 'psysLineComment')
call s:Check('extern sparks', 'extern', 'psysStorage')
call s:Check('extern sparks', 'float', 'psysType')
call s:Check('extern sparks', '50', 'psysNumber')
call s:Check('fn gravity', 'gravity', 'psysDeclName')
call s:Check('fn gravity', '->', 'psysArrow')
call s:Check('fn gravity', 'vec3 =', 'psysType')
call s:Check('fn gravity', 'vec3(', 'psysBuiltin')
call s:Check('fn gravity', '9.82', 'psysNumber')
call s:Check('object spark', 'spark', 'psysDeclName')
call s:Check('pos = snapshot(ipos)', 'snapshot', 'psysTemporal')
call s:Check('vel = origin', 'origin', 'psysConstant')
call s:Check('point(pos, mix', 'point', 'psysKeyword')
call s:Check('point(pos, mix', 'mix', 'psysBuiltin')
call s:Check('point(pos, mix', 'green', 'psysConstant')
call s:Check('point(pos, mix', 'age', 'psysVariable')
call s:Check('kill when age', 'kill', 'psysKeyword')
call s:Check('emit spark(pos)', 'spark', 'psysObjectRef')
call s:Check('emit spark(pos)', 'per', 'psysKeyword')
call s:Check('when vel.y < 0', 'y <', 'psysSwizzle')
call s:Check('sprite(pos, vec4(tint', 'sprite', 'psysKeyword')
call s:Check('@shape(star)', '@shape', 'psysAttribute')
call s:Check('nrand() * 2', 'nrand', 'psysBuiltin')
call s:Check('spawn launcher', 'spawn', 'psysKeyword')

edit editor-support/vscode/test/showcase.psys
call s:Check('/* Every kind', 'Every', 'psysBlockComment')
call s:Check('import "', '"', 'psysString')
call s:Check('@integrator(rk4)', '@integrator', 'psysAttribute')
call s:Check('@integrator(rk4)', 'rk4', 'psysIntegrator')
call s:Check('const numbers', '.5 +', 'psysNumber')
call s:Check('const numbers', '1.5e-3', 'psysNumber')
call s:Check('const numbers', '.5E+2', 'psysNumber')
call s:Check('trigger burst', 'burst', 'psysDeclName')
call s:Check('trigger burst', 'point', 'psysType')
call s:Check('heat = 1 ->', '->', 'psysArrow')
call s:Check('when age > 1 &&', '&&', 'psysOperator')
call s:Check('c = if shell.alive', 'if', 'psysConditional')
call s:Check('kill when age > 0.5', 'true', 'psysBoolean')

" A built-in's name that is not called is an equation's name or a component.
enew
setfiletype psys
call setline(1, ['@ integrator ( midpoint )', 'object o {', '    length = 2;', '    step = 1;',
      \ '    sign = c.rgba;', '    d = length(c.xyz) + step(0.5, sign.x);', '}'])
call s:Check('@ integrator', 'midpoint', 'psysIntegrator')
call s:Check('    length = 2', 'length', '')
call s:Check('    step = 1', 'step', '')
call s:Check('    sign = c.rgba', 'sign', '')
call s:Check('    sign = c.rgba', 'rgba', 'psysSwizzle')
call s:Check('d = length(', 'length', 'psysBuiltin')
call s:Check('d = length(', 'step', 'psysBuiltin')

" Indentation (gg=G) is the layout psysc fmt prints: every sample and library file,
" its lines' leading white space taken away, comes back as it was.
for s:file in glob('samples/*.psys', 0, 1) + glob('library/std/*.psys', 0, 1)
  execute 'edit! ' . s:file
  let s:want = getline(1, '$')
  silent %s/^\s\+//e
  normal! gg=G
  let s:got = getline(1, '$')
  for s:i in range(len(s:want))
    if s:got[s:i] !=# s:want[s:i]
      call add(s:failures, printf('%s line %d indented as `%s`, psysc fmt has `%s`', s:file, s:i + 1, s:got[s:i], s:want[s:i]))
      break
    endif
  endfor
  call add(s:report, printf('indent %s: %d lines', fnamemodify(s:file, ':t'), len(s:want)))
  set nomodified
endfor
" A typed-out statement: a label-like `pos: point` is no C label, the line after an
" attribute is no continuation, and indents are spaces.
enew
setfiletype psys
call setline(1, ['@capacity(100000)', 'object o {', 'pos: vec3 = origin +', 'vec3(1,', '2, 3);', '}'])
normal! gg=G
let s:typed = getline(1, '$')
let s:expected = ['@capacity(100000)', 'object o {', '    pos: vec3 = origin +', '        vec3(1,', '            2, 3);', '}']
if s:typed !=# s:expected
  call add(s:failures, 'typed statement indented as ' . string(s:typed))
endif
if &shiftwidth != 4 || !&expandtab
  call add(s:failures, printf('shiftwidth %d, expandtab %d', &shiftwidth, &expandtab))
endif

call writefile(s:report + map(copy(s:failures), '"FAIL: " . v:val'), $PSYS_VIM_OUT)
if empty(s:failures)
  qall!
endif
cquit!
