"""English instruction -> behaviour Program (rule-based): lexicon tables, grammar, step building, parser, latency bench."""
