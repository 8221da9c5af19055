// The .psys language: the concrete syntax.
//
// The grammar only says what is well formed; names, types, arity and where a construct
// may appear are checked in frontend/ so that those errors get located, worded
// diagnostics instead of parse errors. docs/language.md is the user's reference.
grammar Psys;

// ---------------------------------------------------------------- files

file        : topItem* EOF ;

topItem     : importDecl
            | fileAttribute
            | constDecl
            | fnDecl
            | externDecl
            | triggerDecl
            | objectDecl
            | spawnDecl
            ;

importDecl  : 'import' STRING ';' ;

// `@integrator(rk4);` at file level applies to every object of the file.
fileAttribute : attribute ';' ;

// `@texture("flame.png", 4, 4)`: a file name may come first.
attribute   : '@' IDENT ( '(' ( ( STRING | expr ) ( ',' expr )* )? ')' )? ;

constDecl   : 'const' IDENT ( ':' typeRef )? '=' expr ';' ;

fnDecl      : 'fn' IDENT '(' paramList? ')' ( '->' typeRef )? fnBody ;
fnBody      : '=' expr ';'                                   # fnExprBody
            | '{' ( letStmt )* expr '}'                      # fnBlockBody
            ;
letStmt     : 'let' IDENT ( ':' typeRef )? '=' expr ';' ;

externDecl  : 'extern' IDENT ':' typeRef ( '=' expr )? ( 'range' '(' expr ',' expr ')' )? ';' ;

triggerDecl : 'trigger' IDENT ( '(' paramList? ')' )? '{' command* '}' ;

objectDecl  : attribute* 'object' IDENT ( '(' paramList? ')' )? '{' objectItem* '}' ;

spawnDecl   : 'spawn' IDENT ( '(' argList? ')' )? ';' ;

paramList   : param ( ',' param )* ;
param       : IDENT ':' typeRef ;

typeRef     : ( IDENT | 'point' )                            # namedType
            | '(' typeRef ( ',' typeRef )+ ')'               # tupleType
            ;

// ---------------------------------------------------------------- objects

objectItem  : equation
            | command
            | objectDecl
            ;

// `pos = …;`, `pos: vec3 = …;` or the composite `(pos, vel) = …;`
equation    : IDENT ( ':' typeRef )? '=' expr ';'                  # singleEquation
            | '(' IDENT ( ',' IDENT )+ ')' '=' expr ';'            # tupleEquation
            ;

command     : drawing=( 'point' | 'sprite' | 'streak' | 'trail' ) '(' argList? ')' ';'      # drawCmd
            | 'kill' ( 'when' expr )? ';'                                       # killCmd
            | 'emit' IDENT ( '(' argList? ')' )? emitRate? emitCount? ';'        # emitCmd
            | 'notify' STRING ( '(' argList? ')' )? ';'                         # notifyCmd
            | 'when' expr '{' command* '}'                                      # whenCmd
            | 'on' IDENT '{' command* '}'                                       # onCmd
            ;
emitRate    : 'at' expr 'per' 'second' ;
emitCount   : 'count' expr ;

argList     : expr ( ',' expr )* ;

// ---------------------------------------------------------------- expressions
// Lowest precedence first. `init -> next` binds loosest (as in Lustre), so
// `v = ivel -> prev(v) + a * dt;` reads as `ivel -> (prev(v) + a * dt)`.

expr        : conditional ( '->' expr )? ;

conditional : logicalOr ( '?' expr ':' conditional )?                # ternaryExpr
            | 'if' expr 'then' expr 'else' conditional               # ifExpr
            ;

logicalOr   : logicalAnd ( '||' logicalAnd )* ;
logicalAnd  : equality ( '&&' equality )* ;
equality    : comparison ( ( '==' | '!=' ) comparison )* ;
comparison  : additive ( ( '<' | '<=' | '>' | '>=' ) additive )* ;
additive    : multiplicative ( ( '+' | '-' ) multiplicative )* ;
multiplicative : unary ( ( '*' | '/' | '%' ) unary )* ;
unary       : ( '-' | '!' | '+' ) unary                              # prefixExpr
            | postfix                                                # postfixOnly
            ;
postfix     : primary ( '.' IDENT )* ;

primary     : NUMBER                                                 # numberLit
            | ( 'true' | 'false' )                                   # boolLit
            | IDENT '(' argList? ')'                                 # callExpr
            | IDENT                                                  # nameExpr
            | '(' expr ( ',' expr )* ')'                             # parenExpr
            ;
// One rule for `(e)` and the tuple `(a, b)`: telling them apart needs no look-ahead, so a
// syntax error inside is reported where it is, not at the opening parenthesis.

// ---------------------------------------------------------------- tokens

NUMBER      : DIGITS ( '.' DIGITS? )? EXPONENT?
            | '.' DIGITS EXPONENT?
            ;
fragment DIGITS   : [0-9]+ ;
fragment EXPONENT : [eE] [+-]? DIGITS ;

STRING      : '"' ( ~["\\\r\n] | '\\' . )* '"' ;

IDENT       : [a-zA-Z_] [a-zA-Z_0-9]* ;

LINE_COMMENT  : '//' ~[\r\n]* -> skip ;
BLOCK_COMMENT : '/*' .*? '*/' -> skip ;
WS          : [ \t\r\n]+ -> skip ;

// Anything else reaches the parser as one token, so the front end words the error.
UNKNOWN_CHAR : . ;
