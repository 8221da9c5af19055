" Vim syntax file for psys (.psys): the categories of the VS Code TextMate grammar
" (editor-support/vscode/syntaxes/psys.tmLanguage.json), the same words.
if exists('b:current_syntax')
  finish
endif


syn keyword psysStorage object fn trigger extern const let
syn keyword psysKeyword import spawn emit notify kill when on at per second count range sprite streak trail
syn keyword psysConditional if then else
syn keyword psysBoolean true false
" `point` and `vec3` are types, unless called: then a command and a constructor.
syn keyword psysType bool float scalar vector color
syn match psysType "\<\%(point\|vec[234]\)\>\%(\s*(\)\@!"
syn match psysKeyword "\<point\ze\s*("
" A built-in function only where it is called: `length = 2;` names an equation, `c.rgba`
" reads components.
syn match psysBuiltin "\<\%(sin\|cos\|tan\|asin\|acos\|atan\|atan2\|tanh\|exp\|log\|pow\|sqrt\|abs\|sign\|floor\|ceil\|round\|fract\|hash\|mod\)\ze\s*("
syn match psysBuiltin "\<\%(near_sum\|near_min\|near_max\|near_count\)\ze\s*("
syn match psysBuiltin "\<\%(min\|max\|clamp\|saturate\|mix\|lerp\|step\|smoothstep\|radians\|degrees\|length\|distance\|dot\)\ze\s*("
syn match psysBuiltin "\<\%(normalize\|reflect\|cross\|rotate_x\|rotate_y\|rotate_z\|rgba\)\ze\s*("
syn match psysBuiltin "\<\%(rand\|rand2\|rand3\|rand4\|nrand\|nrand2\|nrand3\|nrand4\)\ze\s*("
syn match psysBuiltin "\<vec[234]\ze\s*("
syn keyword psysTemporal integrate derive snapshot prev
syn keyword psysConstant pi tau origin red green blue white black grey gray yellow cyan magenta orange purple
" `transparent` is an option of :syn keyword, so it is matched instead.
syn match psysConstant "\<transparent\>"
syn keyword psysVariable age time dt

" Numbers in every form the lexer reads: 1, 1., 1.5, .5, 1e5, 1.5e-3, .5E+2.
syn match psysNumber "\<\d\+\%(\.\d*\)\=\%([eE][+-]\=\d\+\)\=\%(\w\)\@!"
syn match psysNumber "\%(\w\)\@<!\.\d\+\%([eE][+-]\=\d\+\)\="

syn match psysAttribute "@\s*\h\w*"
syn match psysIntegrator "\%(@\s*integrator\s*(\s*\)\@<=\h\w*"
syn match psysDeclName "\%(\<\%(object\|fn\|trigger\)\s\+\)\@<=\h\w*"
syn match psysObjectRef "\%(\<\%(emit\|spawn\)\s\+\)\@<=\h\w*"
syn match psysOperator "==\|!=\|<=\|>=\|&&\|||\|[-+*/%<>=!?:]"
syn match psysSwizzle "\.\@<=\%([xyzw]\{1,4}\|[rgba]\{1,4}\)\>"
syn match psysArrow "->"

" Last, so that they win over the operators `/` and `*` that start at the same place.
syn keyword psysTodo contained TODO FIXME XXX NOTE
syn match psysLineComment "//.*$" contains=psysTodo,@Spell
syn region psysBlockComment start="/\*" end="\*/" contains=psysTodo,@Spell
syn region psysString start=+"+ skip=+\\.+ end=+"\|$+

hi def link psysTodo Todo
hi def link psysLineComment Comment
hi def link psysBlockComment Comment
hi def link psysString String
hi def link psysStorage StorageClass
hi def link psysKeyword Keyword
hi def link psysConditional Conditional
hi def link psysBoolean Boolean
hi def link psysType Type
hi def link psysBuiltin Function
hi def link psysTemporal Special
hi def link psysConstant Constant
hi def link psysVariable Identifier
hi def link psysNumber Float
hi def link psysAttribute PreProc
hi def link psysIntegrator Constant
hi def link psysDeclName Function
hi def link psysObjectRef Type
hi def link psysArrow Operator
hi def link psysOperator Operator
hi def link psysSwizzle Special

let b:current_syntax = 'psys'
