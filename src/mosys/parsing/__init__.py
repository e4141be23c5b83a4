"""The spec grammars (one tokenizer, one error type, ``tokens.SpecError``) and the types they
produce."""
