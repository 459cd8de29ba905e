"""The core below every stage: the value types and rules several stages share (errors, argument
rules, the contact automaton's rule, contact events, plain values, progress). It imports no stage."""
