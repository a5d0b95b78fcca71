//! Engine multibody model, mounts, coupled system and outputs.
