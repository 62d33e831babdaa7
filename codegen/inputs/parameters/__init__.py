"""Parameter files as users have them, told apart by content, and as records."""
