"""Analysis of results: impact tests against the model, and their plots. Never imports yade."""
