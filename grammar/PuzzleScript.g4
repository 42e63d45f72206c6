// PuzzleScript rule lines.
//
// A rule line reads, informally:
//
//     [+] {direction | late | rigid | random} cellRow+ -> cellRow* {command}
//     cellRow := '[' cell ('|' cell)* ']'
//     cell    := {[modifier] name | '...'}
//
// The section structure, nested comments and all other line kinds are read
// by psc's scanner (compiler/parse/Scanner.*), which reproduces the
// reference tokenizer's line-by-line state.  This grammar covers what the
// reference compiler re-reads from each stored rule line: it splits the
// line into tokens (after padding '[', ']', '|' and '->' with spaces, as the
// reference does) and separates the prefix, everything before the first '[',
// from the body.  compiler/parse/RuleReader.* then reads the body with the
// reference's own acceptance rules, because malformed rules are sometimes
// warnings that drop the rule and sometimes errors, and psc must agree.

grammar PuzzleScript;

ruleLine   : rulePrefix ruleBody EOF ;

// Directions and flags that apply to the whole rule, and a leading '+' that
// joins the previous rule's group.
rulePrefix : prefixToken* ;
prefixToken: PLUS | WORD | RBRACKET | BAR | ARROW ;

// From the first '[' on: cell rows, the arrow and the commands.
ruleBody   : (LBRACKET bodyToken*)? ;
bodyToken  : LBRACKET | RBRACKET | BAR | ARROW | PLUS | WORD ;

LBRACKET : '[' ;
RBRACKET : ']' ;
BAR      : '|' ;
ARROW    : '->' ;
PLUS     : '+' ;
// Words are separated by JavaScript's \s characters.
WORD     : ~[ \t\n\u000B\f\r\u00A0\u1680\u2000-\u200A\u2028\u2029\u202F\u205F\u3000\uFEFF]+ ;
SPACE    : [ \t\n\u000B\f\r\u00A0\u1680\u2000-\u200A\u2028\u2029\u202F\u205F\u3000\uFEFF]+ -> skip ;
