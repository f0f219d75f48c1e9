"""English instruction -> behaviour Program (rule-based): lexicon tables, parser, latency bench."""
