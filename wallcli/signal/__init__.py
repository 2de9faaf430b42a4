"""The method on plain arrays: exact block sums, mean removal, space-time plots, amplification, and the networks' windows."""
