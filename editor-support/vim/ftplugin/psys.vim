" psys: comments, four-space indentation, and `:make` through psysc check (compiler/psys.vim).
if exists('b:did_ftplugin')
  finish
endif
let b:did_ftplugin = 1

setlocal commentstring=//\ %s
setlocal comments=s1:/*,mb:*,ex:*/,://
setlocal formatoptions-=t formatoptions+=croql
" Four spaces a level, as `psysc fmt` lays it out (indent/psys.vim indents so).
setlocal shiftwidth=4 softtabstop=4 expandtab
setlocal suffixesadd=.psys
setlocal iskeyword=@,48-57,_
compiler psys

let b:undo_ftplugin = 'setlocal commentstring< comments< formatoptions< shiftwidth< softtabstop< expandtab< suffixesadd< iskeyword< makeprg< errorformat<'
