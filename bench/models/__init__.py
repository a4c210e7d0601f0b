"""Model families the benches generate (a model file per member, written by the bench)."""
