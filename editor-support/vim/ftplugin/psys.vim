" psys: comments, indentation, and `:make` through psysc check (compiler/psys.vim).
if exists('b:did_ftplugin')
  finish
endif
let b:did_ftplugin = 1

setlocal commentstring=//\ %s
setlocal comments=s1:/*,mb:*,ex:*/,://
setlocal formatoptions-=t formatoptions+=croql
setlocal cindent cinoptions=(s,m1
setlocal suffixesadd=.psys
setlocal iskeyword=@,48-57,_
compiler psys

let b:undo_ftplugin = 'setlocal commentstring< comments< formatoptions< cindent< cinoptions< suffixesadd< iskeyword< makeprg< errorformat<'
