"""What a user writes: scenes, studies and materials (the study vocabulary and its checks)."""
