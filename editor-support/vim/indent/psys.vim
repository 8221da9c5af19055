" Vim indent file for psys (.psys): the layout `psysc fmt` prints, so `gg=G` and the
" formatter agree. A statement starts at its block's level (four spaces a level); a line
" inside a statement is one level past the line of the innermost bracket still open, or
" past the statement's first line; a line that starts with `)` or `}` goes back to the
" line that opened it.
if exists('b:did_indent')
  finish
endif
let b:did_indent = 1

setlocal indentexpr=GetPsysIndent(v:lnum)
setlocal indentkeys=0{,0},0),!^F,o,O
setlocal nolisp nosmartindent nocindent autoindent
let b:undo_indent = 'setlocal indentexpr< indentkeys< lisp< smartindent< cindent< autoindent<'

if exists('*GetPsysIndent')
  finish
endif

function! s:InCommentOrString(lnum, col) abort
  return synIDattr(synID(a:lnum, a:col, 0), 'name') =~# 'Comment\|String'
endfunction

" A line's code: without its `//` comment and trailing white space.
function! s:Code(lnum) abort
  return substitute(substitute(getline(a:lnum), '//.*$', '', ''), '\s\+$', '', '')
endfunction

" The nearest line above `lnum` that holds code (not blank, not only a comment).
function! s:PrevCode(lnum) abort
  let l = prevnonblank(a:lnum - 1)
  while l > 0 && (s:Code(l) =~# '^\s*$' || s:InCommentOrString(l, match(getline(l), '\S') + 1))
    let l = prevnonblank(l - 1)
  endwhile
  return l
endfunction

" Whether the statement that `lnum` is part of ends with it: `;`, `{`, `}`, or an attribute
" on a line of its own.
function! s:EndsStatement(lnum) abort
  let code = s:Code(a:lnum)
  return a:lnum == 0 || code =~# '[;{}]$' || code =~# '^\s*@\s*\h\w*\s*\%((.*)\)\=$'
endfunction

" The first line of the statement `lnum` is in (a line that closes a block starts its own:
" a fn's last expression before it has no `;`).
function! s:StatementStart(lnum) abort
  let l = a:lnum
  if s:Code(l) =~# '^\s*}'
    return l
  endif
  let p = s:PrevCode(l)
  while p > 0 && !s:EndsStatement(p)
    let l = p
    let p = s:PrevCode(l)
  endwhile
  return l
endfunction

function! GetPsysIndent(lnum) abort
  let skip = 's:InCommentOrString(line("."), col("."))'
  let line = getline(a:lnum)
  let prev = s:PrevCode(a:lnum)
  if prev == 0
    return 0
  endif
  let save = getpos('.')
  try
    call cursor(a:lnum, 1)
    if line =~# '^\s*}'
      call cursor(a:lnum, match(line, '}') + 1)
      let open = searchpair('{', '', '}', 'bnW', skip)
      return open > 0 ? indent(s:StatementStart(open)) : 0
    endif
    if line =~# '^\s*)'
      call cursor(a:lnum, match(line, ')') + 1)
      let open = searchpair('(', '', ')', 'bnW', skip)
      return open > 0 ? indent(open) : indent(prev)
    endif
    if s:EndsStatement(prev)
      let base = indent(s:StatementStart(prev))
      if line =~# '^\s*{'
        return base
      endif
      return s:Code(prev) =~# '{$' ? base + shiftwidth() : base
    endif
    " Inside a statement.
    let open = searchpair('(', '', ')', 'bnW', skip)
    if open > 0
      return indent(open) + shiftwidth()
    endif
    return indent(s:StatementStart(prev)) + (line =~# '^\s*{' ? 0 : shiftwidth())
  finally
    call setpos('.', save)
  endtry
endfunction
